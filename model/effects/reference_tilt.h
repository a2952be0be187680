#pragma once
// The reference pattern tilted: a Kinect reads disparity against a speckle
// image stored at the factory on a plane at a known distance. Stored off
// square, or with the projector's pattern since turned slightly against it,
// every pixel's disparity is off by a constant that changes linearly over the
// image and not with depth: offset = tilt_x x + tilt_y y (x, y normalized;
// the offset at the centre is the base form's). spatial_field follows the
// same plane and more, with some 40 parameters that a session's 15-25 poses
// do not pin down where few boards reached (bench/results/hunt.md, linear offset).
#include "model/effect.h"

namespace speckle::model {
struct ReferenceTilt {
  static constexpr const char* kName = "reference_tilt";
  static constexpr const char* kDoc =
      "disparity offset linear over the image, constant in depth: the reference pattern off square to the sensor";
  // An offset constant in raw is a tilt of disparity, which a driver's
  // millimetres no longer show as a plane.
  static constexpr const char* kUnits = "raw";
  static std::vector<EffectParameter> Parameters() {
    return {{"tilt_x", "raw", 0, -50, 50}, {"tilt_y", "raw", 0, -50, 50}};
  }
  static std::vector<std::string> CovariatesRead() { return {"x", "y"}; }
  template <typename T>
  static T RawOffset(const T* p, const Covariates& c) {
    return p[0] * c.x + p[1] * c.y;
  }
};
SPECKLE_MODEL_EFFECT(ReferenceTilt)
}  // namespace speckle::model
