#pragma once
// The diagnosis as one call: the floor, the coverage and the covariate
// profiles of the held-out residuals (analysis), then the candidate effects
// fitted and ranked (candidates.h), then the verdict (verdict.h).
#include <vector>

#include "lab/diagnosis/diagnosis.h"

namespace speckle {

// `perturbations` (per camera input, every sample's depth moved by one sigma;
// may be empty) let the diagnosis tell the cameras' uncertainty from effects.
// `grid_std_error_raw`: when the samples went through an undistortion grid,
// its correction's standard error at each (UndistortionGrid::StdErrorAt),
// which the floor counts; else empty. `judge`: where candidates are held
// out (empty: the depth fit, the cameras held or moved by `perturbations`).
Diagnosis RunModelDiagnosis(const DiagnosisOptions& options, const std::vector<PairedSample>& samples,
                            const DepthFit& fit, const DepthPerturbations& perturbations = {},
                            const std::vector<double>& grid_std_error_raw = {}, const HeldOutJudge& judge = {});

}  // namespace speckle
