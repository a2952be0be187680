#pragma once
// The residual blocks of a depth-model problem: each sample's row holding the
// parameter blocks it reaches, in batches, and the effects' priors, bounds
// and frozen blocks.
#include <vector>

#include "lab/fit/solve.h"

namespace speckle::fitting {

// Which effects get one Ceres block per parameter: in a large model, those
// that say which parameters each sample reaches (effect.h's Support).
std::vector<bool> SplitEffects(const DepthFitOptions& options, const model::DepthModel& m);

// One row per sample, holding the blocks it reaches, in batches of samples
// that reach the same blocks (ResidualBatch). Returns whether some sample
// reaches every parameter of a split effect.
bool AddSampleResiduals(const DepthFitOptions& options, const std::vector<const PairedSample*>& samples,
                        const std::vector<double>* depths, const CameraFreedom* freedom, const std::vector<bool>& split,
                        Solved& out);

// Frozen effects held, priors and bounds set: on the whole block, or on each
// parameter's block of a split effect.
void ConstrainEffects(const model::ModelDefinition& definition, const std::vector<bool>& split, Solved& out);
// The same in any problem: effect_blocks[k] is effect k's first parameter.
// Returns the priors' residual blocks, which a covariance computed from the
// problem's residuals must count (a spline's weak prior is what separates it
// from the plane terms beside it).
std::vector<ceres::ResidualBlockId> ConstrainEffects(const model::ModelDefinition& definition,
                                                     const model::DepthModel& m,
                                                     const std::vector<double*>& effect_blocks,
                                                     const std::vector<bool>& split, ceres::Problem& problem);

}  // namespace speckle::fitting
