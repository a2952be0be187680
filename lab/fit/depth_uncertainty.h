#pragma once
// The depth error bars a calibration carries: what its parameters'
// covariance (the fit's own and the cameras' uncertainty moved through it)
// implies for depth at the image centre: over the paired raw range, and
// beyond it over the range a Kinect is used at, where the model extrapolates.
#include <optional>
#include <string>
#include <vector>

#include "lab/model_lab.h"

namespace speckle {

struct DepthSigma {
  double raw = 0;
  double depth_m = 0;
  double sigma_mm = 0;
  bool extrapolated = false;  // outside the paired samples' raw range
};

// Where the sensor is used: the extrapolated rows are every `step_m` from
// `near_m` to `far_m` (the Kinect's usable range, ../shared/docs/domain.md)
// that lies outside the paired depths.
struct DepthUncertaintyOptions {
  double near_m = 0.5;
  double far_m = 3.5;
  double step_m = 0.5;
};

// Eleven rows from the lowest to the highest raw value of `samples`, and the
// extrapolated ones; sorted by depth.
std::vector<DepthSigma> DepthUncertainty(const NamedFit& fit, const std::vector<PairedSample>& samples,
                                         const DepthUncertaintyOptions& options = {});

// One line for a terminal summary: the depth sigma at both ends of the paired
// range, and when it exceeds `loose_share` of the depth, what sets it and
// what narrows it (`cameras`: the calibration's cameras); then, when there
// are extrapolated rows beyond it, the sigma at the farthest.
std::string DepthUncertaintyLine(const std::vector<DepthSigma>& rows, const CameraCalibration& cameras,
                                 double loose_share = 0.003);

}  // namespace speckle
