#pragma once
// Planar snapshots are meant to be square to the sensor, but a wall is never
// exactly so: each snapshot is tilted by a small random angle about the
// image axes, which shows as a raw-value ramp across the snapshot.
#include <random>

#include "simulator/sim_effect.h"

namespace speckle::sim {

class MisalignedSnapshots : public SimEffect {
 public:
  static constexpr const char* kName = "misaligned_snapshots";
  static constexpr const char* kDoc = "wall snapshots tilted a little from square to the sensor";

  MisalignedSnapshots(JsonFields& f, const SceneContext& c)
      : max_tilt_deg_(f.RequiredInRange("max_tilt_deg", 0, 20)), seed_(c.seed) {}

  nlohmann::json Parameters() const override { return {{"max_tilt_deg", max_tilt_deg_}}; }
  void MoveTarget(const FrameContext& frame, TargetPose& colour, TargetPose& depth) const override {
    if (frame.recording != SimRecording::kPlanar) return;
    std::mt19937_64 rng(seed_ * 131 + static_cast<std::uint64_t>(frame.pose) + 5);
    std::uniform_real_distribution<double> tilt(-max_tilt_deg_ * M_PI / 180, max_tilt_deg_ * M_PI / 180);
    const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(tilt(rng), Eigen::Vector3d::UnitX()) *
                                      Eigen::AngleAxisd(tilt(rng), Eigen::Vector3d::UnitY()))
                                         .toRotationMatrix();
    colour.ir_from_target.linear() = rotation * colour.ir_from_target.linear();
    depth = colour;
  }

 private:
  double max_tilt_deg_;
  std::uint64_t seed_;
};
SPECKLE_SIM_EFFECT(MisalignedSnapshots)

}  // namespace speckle::sim
