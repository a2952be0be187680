#pragma once
// Colour and depth are exposed at different instants while a hand-held board
// moves: the depth image sees each board point where it was `delay` seconds
// after the colour image did, so its raw value is off by delay times how
// fast that raw value changes (raw_rate: the same board point in the
// neighbouring depth frames). The extrinsics fit the same delay from the
// board's outline (depth_delay_s in calibration.json); the two should agree.
#include "model/effect.h"

namespace speckle::model {
struct CaptureTimeOffset {
  static constexpr const char* kName = "capture_time_offset";
  static constexpr const char* kDoc = "depth exposed at another instant than colour while the board moves";
  static std::vector<EffectParameter> Parameters() { return {{"delay", "s", 0, -0.5, 0.5}}; }
  static std::vector<std::string> CovariatesRead() { return {"raw_rate"}; }
  template <typename T>
  static T RawOffset(const T* p, const Covariates& c) {
    return p[0] * c.raw_rate;
  }
};
SPECKLE_MODEL_EFFECT(CaptureTimeOffset)
}  // namespace speckle::model
