#pragma once
// Wide-angle billowing. An add-on wide-angle adapter makes a flat wall look
// convex in depth: raw values grow towards the periphery, more horizontally
// than vertically, and the growth in raw units shrinks with distance. The
// thesis (Eq. 4.2) fits each wall snapshot with the hyperboloid
//   r_measured^2 = r^2 + bx (x - xc)^2 + by (y - yc)^2,
// x, y being normalized undistorted image coordinates; this effect applies it.
#include <cmath>

#include "simulator/sim_effect.h"

namespace speckle::sim {

class RadialBillow : public SimEffect {
 public:
  static constexpr const char* kName = "radial_billow";
  static constexpr const char* kDoc =
      "wide-angle billowing: flat walls bulge in raw value towards the edges (thesis Eq. 4.2)";

  RadialBillow(JsonFields& f, const SceneContext&)
      : bx_(f.RequiredInRange("bx_raw2", 0, 1e7)),
        by_(f.RequiredInRange("by_raw2", 0, 1e7)),
        xc_(f.OptionalInRange("xc", 0, -0.5, 0.5)),
        yc_(f.OptionalInRange("yc", 0, -0.5, 0.5)) {}

  nlohmann::json Parameters() const override { return {{"bx_raw2", bx_}, {"by_raw2", by_}, {"xc", xc_}, {"yc", yc_}}; }
  double RawOffset(const DepthSample& s) const override {
    const double dx = s.x - xc_, dy = s.y - yc_;
    return std::sqrt(s.raw * s.raw + bx_ * dx * dx + by_ * dy * dy) - s.raw;
  }

 private:
  double bx_, by_, xc_, yc_;
};
SPECKLE_SIM_EFFECT(RadialBillow)

}  // namespace speckle::sim
