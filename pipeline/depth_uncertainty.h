#pragma once
// The depth error bars a calibration carries: what its parameters'
// covariance (the fit's own and the cameras' uncertainty moved through it)
// implies for depth over the paired raw range, at the image centre.
#include <optional>
#include <string>
#include <vector>

#include "pipeline/model_lab.h"

namespace speckle {

struct DepthSigma {
  double raw = 0;
  double depth_m = 0;
  double sigma_mm = 0;
};

// Eleven rows from the lowest to the highest raw value of `samples`.
std::vector<DepthSigma> DepthUncertainty(const NamedFit& fit, const std::vector<PairedSample>& samples);

// One line for a terminal summary: the depth sigma at both ends of the range,
// and when it exceeds `loose_share` of the depth, what sets it and what
// narrows it (`cameras`: the calibration's cameras).
std::string DepthUncertaintyLine(const std::vector<DepthSigma>& rows, const CameraCalibration& cameras,
                                 double loose_share = 0.003);

}  // namespace speckle
