#pragma once
// Colour and depth are not exposed at the same instant. A hand-held board is
// never quite still: it sways at some cm/s, each pose along its own
// direction, so the depth image sees it where it was `offset_s` after the
// colour image did. Its outline lags (what the extrinsics see) and, where the
// sway has a part along the depth axis, every board point's depth differs
// from the colour pose's by that speed times the offset (what the depth model
// sees).
#include <random>

#include "simulator/sim_effect.h"

namespace speckle::sim {

class CaptureTimeOffset : public SimEffect {
 public:
  static constexpr const char* kName = "capture_time_offset";
  static constexpr const char* kDoc = "depth exposed after colour while a hand-held board drifts";

  CaptureTimeOffset(JsonFields& f, const SceneContext& c)
      : offset_s_(f.RequiredInRange("offset_s", -0.5, 0.5)),
        speed_(f.RequiredInRange("board_speed_m_s", 0, 2)),
        seed_(c.seed) {}

  nlohmann::json Parameters() const override { return {{"offset_s", offset_s_}, {"board_speed_m_s", speed_}}; }
  void MoveTarget(const FrameContext& frame, TargetPose& colour, TargetPose& depth) const override {
    if (!colour.is_board) return;
    // Each pose sways along its own direction, uniform over the sphere.
    std::mt19937_64 rng(seed_ * 31 + static_cast<std::uint64_t>(frame.pose) + 17);
    std::normal_distribution<double> normal(0, 1);
    Eigen::Vector3d direction;
    for (int i = 0; i < 3; ++i) direction[i] = normal(rng);
    const Eigen::Vector3d velocity = direction.normalized() * speed_;
    depth = colour;
    colour.ir_from_target.pretranslate(velocity * frame.seconds_into_pose);
    depth.ir_from_target.pretranslate(velocity * (frame.seconds_into_pose + offset_s_));
  }

 private:
  double offset_s_, speed_;
  std::uint64_t seed_;
};
SPECKLE_SIM_EFFECT(CaptureTimeOffset)

}  // namespace speckle::sim
