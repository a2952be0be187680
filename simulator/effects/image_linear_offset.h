#pragma once
// A raw offset that changes linearly across the image, as a reference
// pattern stored off square (or a projector pattern slightly rotated against
// it) makes. The catalogue's reference_tilt is its plane (offset_raw goes to
// the base form) and the smooth spatial field follows it with many more
// parameters; the depth-grid offset only mimics it through depth gradients.
//   delta_r = offset + slope_x * x + slope_y * y   (x, y normalized image coordinates)
#include "simulator/sim_effect.h"

namespace speckle::sim {
class ImageLinearOffset : public SimEffect {
 public:
  static constexpr const char* kName = "image_linear_offset";
  static constexpr const char* kDoc = "raw offset linear over the normalized image (the model's reference_tilt)";
  ImageLinearOffset(JsonFields& f, const SceneContext&)
      : offset_(f.OptionalInRange("offset_raw", 0, -20, 20)),
        slope_x_(f.RequiredInRange("slope_x_raw", -50, 50)),
        slope_y_(f.RequiredInRange("slope_y_raw", -50, 50)) {}
  nlohmann::json Parameters() const override {
    return {{"offset_raw", offset_}, {"slope_x_raw", slope_x_}, {"slope_y_raw", slope_y_}};
  }
  double RawOffset(const DepthSample& s) const override { return offset_ + slope_x_ * s.x + slope_y_ * s.y; }

 private:
  double offset_, slope_x_, slope_y_;
};
SPECKLE_SIM_EFFECT(ImageLinearOffset)
}  // namespace speckle::sim
