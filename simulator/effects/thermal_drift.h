#pragma once
// Thermal warm-up: as the projector and IR camera warm over the first tens of
// minutes, the pattern shifts and raw values drift towards a new level:
//   delta_r(t) = amplitude * (1 - exp(-t / time_constant)).
#include <cmath>

#include "simulator/sim_effect.h"

namespace speckle::sim {

class ThermalDrift : public SimEffect {
 public:
  static constexpr const char* kName = "thermal_drift";
  static constexpr const char* kDoc = "raw values drift during warm-up, saturating with a time constant";

  ThermalDrift(JsonFields& f, const SceneContext&)
      : amplitude_(f.RequiredInRange("amplitude_raw", -50, 50)),
        time_constant_(f.RequiredInRange("time_constant_s", 1, 36000)) {}

  nlohmann::json Parameters() const override {
    return {{"amplitude_raw", amplitude_}, {"time_constant_s", time_constant_}};
  }
  double RawOffset(const DepthSample& s) const override {
    return amplitude_ * (1 - std::exp(-s.time_s / time_constant_));
  }

 private:
  double amplitude_, time_constant_;
};
SPECKLE_SIM_EFFECT(ThermalDrift)

}  // namespace speckle::sim
