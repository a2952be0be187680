#pragma once
// The noise floor: the held-out error no depth model can go below with this
// data (the sensor's own scatter, the cameras' uncertainty, the grid's).
#include <vector>

#include "lab/diagnosis/diagnosis.h"

namespace speckle {

NoiseFloor EstimateFloor(const DiagnosisOptions& options, const std::vector<PairedSample>& samples, const DepthFit& fit,
                         const std::vector<double>& grid_std_error_raw);

}  // namespace speckle
