#include "simulator/session_simulator.h"

#include <cmath>
#include <random>

namespace speckle::sim {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

Eigen::Matrix3d Tilt(double about_x_deg, double about_y_deg, double about_z_deg) {
  return (Eigen::AngleAxisd(about_z_deg * kDegToRad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(about_y_deg * kDegToRad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(about_x_deg * kDegToRad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

bool InsideWithMargin(const CameraModel& camera, const Eigen::Vector3d& p, double margin) {
  if (p.z() <= 0.1) return false;
  const Eigen::Vector2d px = camera.Project(p);
  return px.x() > margin && px.y() > margin && px.x() < camera.size.width - margin &&
         px.y() < camera.size.height - margin;
}

// A board pose whose four outer corners are well inside both cameras' images.
TargetPose SampleBoardPose(const Scenario& s, const SensorOptics& optics, std::mt19937_64& rng) {
  const double width = s.rig.squares_x * s.rig.square_size_m;
  const double height = s.rig.squares_y * s.rig.square_size_m;
  std::uniform_real_distribution<double> unit(0, 1), sym(-1, 1);
  for (int attempt = 0; attempt < 1000; ++attempt) {
    const double z = s.depthboard.min_depth_m + unit(rng) * (s.depthboard.max_depth_m - s.depthboard.min_depth_m);
    const double tilt = s.depthboard.max_tilt_deg;
    const Eigen::Matrix3d rotation = Tilt(sym(rng) * tilt, sym(rng) * tilt, sym(rng) * 10);
    // Centre anywhere in the central part of the IR image at depth z.
    const Eigen::Vector3d centre(sym(rng) * 0.35 * z, sym(rng) * 0.25 * z, z);
    TargetPose pose;
    pose.is_board = true;
    pose.ir_from_target.linear() = rotation;
    pose.ir_from_target.translation() = centre - rotation * Eigen::Vector3d(width / 2, height / 2, 0);
    bool visible = true;
    for (const auto& corner : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(width, 0, 0), Eigen::Vector3d(0, height, 0),
                               Eigen::Vector3d(width, height, 0)}) {
      const Eigen::Vector3d in_ir = pose.ir_from_target * corner;
      visible = visible && InsideWithMargin(optics.ir, in_ir, 25) &&
                InsideWithMargin(optics.colour, optics.colour_from_ir * in_ir, 25);
    }
    if (visible) return pose;
  }
  throw std::runtime_error("no board pose fits both cameras; widen depthboard.min_depth_m..max_depth_m");
}

}  // namespace

SessionSimulator::SessionSimulator(const Scenario& scenario)
    : scenario_(scenario), renderer_(OpticsByName(scenario.optics), scenario) {
  std::mt19937_64 rng(scenario.seed);
  const double frame_period = 1.0 / scenario.frame_rate_hz;
  double time = 0;
  for (int pose = 0; pose < scenario.depthboard.poses; ++pose) {
    const TargetPose target = SampleBoardPose(scenario, renderer_.optics(), rng);
    for (int k = 0; k < scenario.depthboard.frames_per_pose; ++k) {
      depthboard_.push_back({static_cast<int>(depthboard_.size()), pose, time + k * frame_period, target});
    }
    time += scenario.depthboard.seconds_between_poses;
  }
  std::uniform_real_distribution<double> sym(-1, 1);
  const PlanarSpec& p = scenario.planar;
  for (int snapshot = 0; snapshot < p.snapshots; ++snapshot) {
    const double z = p.snapshots == 1 ? p.min_depth_m
                                      : p.min_depth_m + (p.max_depth_m - p.min_depth_m) * snapshot / (p.snapshots - 1);
    TargetPose wall;
    wall.is_board = false;
    wall.ir_from_target.linear() = Tilt(sym(rng) * p.max_misalignment_deg, sym(rng) * p.max_misalignment_deg, 0);
    wall.ir_from_target.translation() = Eigen::Vector3d(0, 0, z);
    for (int k = 0; k < p.frames_per_snapshot; ++k) {
      planar_.push_back({static_cast<int>(planar_.size()), snapshot, time + k * frame_period, wall});
    }
    time += scenario.depthboard.seconds_between_poses;
  }
}

SimFrame SessionSimulator::Render(SimRecording which, const SimFrameSpec& spec) const {
  // Each frame has its own noise stream, so rendering order does not matter.
  std::seed_seq seq{scenario_.seed, static_cast<std::uint64_t>(which), static_cast<std::uint64_t>(spec.index)};
  std::mt19937_64 rng(seq);
  SimFrame frame;
  frame.raw_depth = renderer_.RawFromDepth(renderer_.TrueDepth(spec.target), rng);
  frame.colour_rgb = renderer_.Colour(spec.target, rng);
  return frame;
}

}  // namespace speckle::sim
