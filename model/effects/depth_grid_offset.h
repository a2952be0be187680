#pragma once
// The depth image is offset from the IR image by a few pixels (ROS
// kinect_calibration). The pipeline's colour-to-depth extrinsics are fitted
// to the board as the depth image shows it, so they absorb the shift as a
// small rotation (angle = shift / focal length, about 1.7 mrad per pixel).
// That rotation tilts every true depth by z (θx x + θy y), which in raw units
// is offset = (θx x + θy y)(raw - raw∞), raw∞ the raw value of infinite depth
// (-b/a of the reciprocal form; weakly held near a stock Kinect's).
// To the depth image an error in the IR camera's principal point is the same
// shift, so the effect also corrects (and the diagnosis finds) that: which
// of the two it is, the depth samples cannot tell.
#include "model/effect.h"

namespace speckle::model {
struct DepthGridOffset {
  static constexpr const char* kName = "depth_grid_offset";
  static constexpr const char* kDoc =
      "depth image shifted from the IR image (or, the same to the depth image, an error in the IR camera's principal "
      "point), absorbed by the extrinsics as a small rotation";
  static std::vector<EffectParameter> Parameters() {
    return {{"theta_x", "mrad", 0, -30, 30},
            {"theta_y", "mrad", 0, -30, 30},
            {"raw_at_infinity", "raw", 1090, 900, 1400, 100}};
  }
  static std::vector<std::string> CovariatesRead() { return {"x", "y", "raw"}; }
  template <typename T>
  static T RawOffset(const T* p, const Covariates& c) {
    return (p[0] * c.x + p[1] * c.y) * 1e-3 * (c.raw - p[2]);
  }
};
SPECKLE_MODEL_EFFECT(DepthGridOffset)
}  // namespace speckle::model
