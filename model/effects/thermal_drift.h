#pragma once
// Thermal warm-up: raw values drift towards a new level as the projector and
// IR camera warm: offset = amplitude * (1 - exp(-t / time_constant)).
#include "model/effect.h"

namespace speckle::model {
struct ThermalDrift {
  static constexpr const char* kName = "thermal_drift";
  static constexpr const char* kDoc = "raw values drift during warm-up, saturating with a time constant";
  static std::vector<EffectParameter> Parameters() {
    return {{"amplitude", "raw", 0, -50, 50}, {"time_constant", "s", 300, 10, 36000}};
  }
  static std::vector<std::string> CovariatesRead() { return {"time_s"}; }
  template <typename T>
  static T RawOffset(const T* p, const Covariates& c) {
    using std::exp;
    return p[0] * (1.0 - exp(-c.time_s / p[1]));
  }
};
SPECKLE_MODEL_EFFECT(ThermalDrift)
}  // namespace speckle::model
