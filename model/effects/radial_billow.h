#pragma once
// Wide-angle billowing (thesis Eq. 4.2): a flat wall bulges in raw value
// towards the image edges, more horizontally than vertically, less with range:
//   r_measured^2 = r^2 + bx x^2 + by y^2  (x, y normalized undistorted).
#include "model/effect.h"

namespace speckle::model {
struct RadialBillow {
  static constexpr const char* kName = "radial_billow";
  static constexpr const char* kDoc = "wide-angle billowing: raw values grow towards the image edges (thesis Eq. 4.2)";
  static std::vector<EffectParameter> Parameters() {
    return {{"bx", "raw^2", 1000, 0, 1e7}, {"by", "raw^2", 1000, 0, 1e7}};
  }
  static std::vector<std::string> CovariatesRead() { return {"raw", "x", "y"}; }
  template <typename T>
  static T RawOffset(const T* p, const Covariates& c) {
    using std::sqrt;
    // raw_measured = sqrt(r^2 + b.x^2), with r the raw value without billowing.
    const double r = c.raw;
    const T b = p[0] * (c.x * c.x) + p[1] * (c.y * c.y);
    return r - sqrt(r * r - b);
  }
};
SPECKLE_MODEL_EFFECT(RadialBillow)
}  // namespace speckle::model
