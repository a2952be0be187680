#pragma once
// The depth image is not registered to the IR image: it is offset by a few
// pixels (about 3-4 px per the ROS kinect_calibration notes), so depth pixel
// (u, v) shows what the IR camera sees at (u + dx, v + dy). Depth edges move
// by the offset; residuals correlate with the local depth gradient.
#include "simulator/sim_effect.h"

namespace speckle::sim {

class DepthGridOffset : public SimEffect {
 public:
  static constexpr const char* kName = "depth_grid_offset";
  static constexpr const char* kDoc = "depth image offset from the IR image by a few pixels (ROS kinect_calibration)";

  DepthGridOffset(JsonFields& f, const SceneContext&)
      : shift_(f.RequiredInRange("dx_px", -10, 10), f.RequiredInRange("dy_px", -10, 10)) {}

  nlohmann::json Parameters() const override { return {{"dx_px", shift_.x()}, {"dy_px", shift_.y()}}; }
  Eigen::Vector2d DepthGridShift() const override { return shift_; }

 private:
  Eigen::Vector2d shift_;
};
SPECKLE_SIM_EFFECT(DepthGridOffset)

}  // namespace speckle::sim
