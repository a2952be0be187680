#pragma once
// Not in the model's catalogue on purpose: a step in raw value above one
// level, as a firmware lookup-table seam would make. It tests that the
// diagnostics name the covariate along which the model fails (the raw value)
// when no catalogue effect explains it.
//   delta_r = height for raw > level, else 0
#include "simulator/sim_effect.h"

namespace speckle::sim {
class RawStep : public SimEffect {
 public:
  static constexpr const char* kName = "raw_step";
  static constexpr const char* kDoc = "a step in raw value above one level (outside the model catalogue)";
  RawStep(JsonFields& f, const SceneContext&)
      : level_(f.RequiredInRange("level_raw", 300, 1100)), height_(f.RequiredInRange("height_raw", -20, 20)) {}
  nlohmann::json Parameters() const override { return {{"level_raw", level_}, {"height_raw", height_}}; }
  double RawOffset(const DepthSample& s) const override { return s.raw > level_ ? height_ : 0; }

 private:
  double level_, height_;
};
SPECKLE_SIM_EFFECT(RawStep)
}  // namespace speckle::sim
