#pragma once
// Colour and depth are exposed at different instants while a hand-held board
// drifts: the depth image sees the board moved by its image velocity times
// the offset, so offset = -delay * (g_u v_u + g_v v_v) (gradient g of the raw
// image, velocity v of the board in the colour image). This holds where
// samples are read at fixed pixels of the board's plane (board-plane pairing).
// Depthboard-quad pairing follows each board point through the depth quad's
// own pose, and the extrinsics fit the delay itself (depth_delay_s), so there
// only motion along the depth axis would leave a raw error.
#include "model/effect.h"

namespace speckle::model {
struct CaptureTimeOffset {
  static constexpr const char* kName = "capture_time_offset";
  static constexpr const char* kDoc = "depth exposed at another instant than colour while the board moves";
  static std::vector<EffectParameter> Parameters() { return {{"delay", "s", 0, -0.5, 0.5}}; }
  static std::vector<std::string> CovariatesRead() { return {"gradient_u", "gradient_v", "velocity_u", "velocity_v"}; }
  template <typename T>
  static T RawOffset(const T* p, const Covariates& c) {
    return -p[0] * (c.gradient_u * c.velocity_u + c.gradient_v * c.velocity_v);
  }
};
SPECKLE_MODEL_EFFECT(CaptureTimeOffset)
}  // namespace speckle::model
