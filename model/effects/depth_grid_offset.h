#pragma once
// The depth image is offset from the IR image by a few pixels (ROS
// kinect_calibration): pixel (u, v) reads the raw value of (u + dx, v + dy),
// so the error follows the local raw gradient: offset = g_u dx + g_v dy.
#include "model/effect.h"

namespace speckle::model {
struct DepthGridOffset {
  static constexpr const char* kName = "depth_grid_offset";
  static constexpr const char* kDoc = "depth image shifted from the IR image by a few pixels";
  static std::vector<EffectParameter> Parameters() { return {{"dx", "px", 0, -10, 10}, {"dy", "px", 0, -10, 10}}; }
  static std::vector<std::string> CovariatesRead() { return {"gradient_u", "gradient_v"}; }
  template <typename T>
  static T RawOffset(const T* p, const Covariates& c) { return c.gradient_u * p[0] + c.gradient_v * p[1]; }
};
SPECKLE_MODEL_EFFECT(DepthGridOffset)
}  // namespace speckle::model
