#pragma once
// IR reflectivity of the target: dark squares return less of the speckle
// pattern and the correlation is biased, so their raw values are offset:
//   delta_r = bias * (1 - albedo)
// (albedo 0.1 on dark squares, 0.9 on light ones, 0.7 on walls).
#include "simulator/sim_effect.h"

namespace speckle::sim {

class AlbedoBias : public SimEffect {
 public:
  static constexpr const char* kName = "albedo_bias";
  static constexpr const char* kDoc = "dark (low IR albedo) surfaces read biased raw values";

  AlbedoBias(JsonFields& f, const SceneContext&) : bias_(f.RequiredInRange("dark_bias_raw", -30, 30)) {}

  nlohmann::json Parameters() const override { return {{"dark_bias_raw", bias_}}; }
  double RawOffset(const DepthSample& s) const override { return bias_ * (1 - s.albedo); }

 private:
  double bias_;
};
SPECKLE_SIM_EFFECT(AlbedoBias)

}  // namespace speckle::sim
