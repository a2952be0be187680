#pragma once
// The paired samples as a fit sees them: their covariates, their weights,
// subsamples and folds by pose.
#include <cstddef>
#include <vector>

#include "lab/fit/fit_options.h"
#include "model/covariates.h"
#include "stages/records.h"

namespace speckle {

// A sample's covariates as measured (what applying a calibration sees).
model::Covariates CovariatesOf(const PairedSample& s);
// The same with the raw covariate noise-free (PairedSample::fit_raw) when set:
// what fits and residuals in raw units use.
model::Covariates FitCovariatesOf(const PairedSample& s);

// The step that takes an even subsample of at most `at_most` of `count`
// samples (every stride-th; 1 when all fit).
std::size_t EvenStride(std::size_t count, std::size_t at_most);

// Which cross-validation fold holds each sample: poses dealt round-robin.
std::vector<int> FoldsByPose(const std::vector<PairedSample>& samples, int folds);

namespace fitting {

// A sample's weight in the fit: 1, or for a millimetre reading (1 m / z)^2,
// z its reading (see DepthFitOptions::millimetre_readings).
double ReadingWeight(const DepthFitOptions& options, const PairedSample& s);

// The samples by address, as the solver's residuals hold them.
std::vector<const PairedSample*> Pointers(const std::vector<PairedSample>& samples);

}  // namespace fitting
}  // namespace speckle
