#pragma once
// Colour and depth are not exposed at the same instant. A hand-held board is
// never quite still: it sways sideways and up and down (parallel to the image
// plane) at some cm/s, so the depth image sees it where it was `offset_s`
// after the colour image did. A tilted board moved sideways changes the depth
// behind each pixel; the error grows with the board's motion and tilt. (A
// drift within the board's own plane would leave a plane's depths unchanged.)
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
    // Each pose sways along its own direction parallel to the image plane.
    std::mt19937_64 rng(seed_ * 31 + static_cast<std::uint64_t>(frame.pose) + 17);
    const double angle = std::uniform_real_distribution<double>(0, 2 * M_PI)(rng);
    const Eigen::Vector3d velocity = Eigen::Vector3d(std::cos(angle), std::sin(angle), 0) * speed_;
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
