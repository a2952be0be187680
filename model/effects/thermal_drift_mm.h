#pragma once
// Thermal warm-up seen through a driver's millimetres (OpenNI, ROS, TUM): the
// projector and IR camera drift in raw disparity steps (thermal_drift), and
// one raw step is 3.07 z^2 mm at z metres (the nominal Kinect relation
// 1/z = -0.0030711 r + 3.3309), so in millimetres the drift grows with depth
// squared: offset = amplitude * (1 - exp(-t / time_constant)) * 3.0711 z^2,
// z the reading in metres. thermal_drift, one offset per time, left 3x the
// noise floor in such a session (bench/results/hunt.md).
#include "model/effect.h"

namespace speckle::model {
struct ThermalDriftMm {
  static constexpr const char* kName = "thermal_drift_mm";
  static constexpr const char* kDoc = "warm-up drift in raw steps, read in millimetres: grows with depth squared";
  static constexpr const char* kUnits = "millimetre";
  static std::vector<EffectParameter> Parameters() {
    return {{"amplitude", "raw", 0, -50, 50}, {"time_constant", "s", 300, 10, 36000}};
  }
  static std::vector<std::string> CovariatesRead() { return {"time_s", "raw"}; }
  template <typename T>
  static T RawOffset(const T* p, const Covariates& c) {
    using std::exp;
    const double z_m = c.raw / 1000;
    return p[0] * (1.0 - exp(-c.time_s / p[1])) * (3.0711 * z_m * z_m);
  }
};
SPECKLE_MODEL_EFFECT(ThermalDriftMm)
}  // namespace speckle::model
