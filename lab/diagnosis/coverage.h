#pragma once
// Where the session's board poses reach the depth image, and whether the
// model has more parameters than they pin down.
#include <vector>

#include "lab/diagnosis/diagnosis.h"

namespace speckle {

Coverage AssessCoverage(const DiagnosisOptions& options, const std::vector<PairedSample>& samples, const DepthFit& fit,
                        double floor_raw, double held_out_rms);

}  // namespace speckle
