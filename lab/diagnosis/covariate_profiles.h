#pragma once
// Covariate profiles: the held-out residuals against every covariate the
// diagnosis reads (the axes' table in covariate_profiles.cc), by sample and,
// for the pose-level axes, by pose mean; and the best raw step.
#include <vector>

#include "lab/diagnosis/diagnosis.h"

namespace speckle {

// d.covariates (most explaining first) and d.step_level_raw, with the
// excess over d.floor that each covariate explains.
void ProfileCovariates(const DiagnosisOptions& options, const std::vector<PairedSample>& samples, const DepthFit& fit,
                       Diagnosis& d);

}  // namespace speckle
