#pragma once
// Cross-validation by pose: the held-out error every model is judged by.
#include <vector>

#include "lab/fit/depth_fit.h"
#include "lab/fit/solve.h"

namespace speckle::fitting {

// Cross-validation by pose: each fold's poses predicted by a fit to the
// others, into fit.held_out_residual_raw and held_out_mm. Returns each usable
// fold's parameters (for the jackknife).
std::vector<std::vector<double>> HoldOutPoses(const DepthFitOptions& options, const model::ModelDefinition& definition,
                                              const std::vector<PairedSample>& samples,
                                              const DepthPerturbations& perturbations,
                                              const CameraFreedom* free_cameras, DepthFit& fit, FitSeconds& seconds);

}  // namespace speckle::fitting
