#include "simulator/session_simulator.h"

#include <cmath>
#include <random>

#include "schemas/errors.h"

namespace speckle::sim {
namespace {

constexpr double kRadiansPerDegree = M_PI / 180.0;

Eigen::Matrix3d Tilt(double about_x_deg, double about_y_deg, double about_z_deg) {
  return (Eigen::AngleAxisd(about_z_deg * kRadiansPerDegree, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(about_y_deg * kRadiansPerDegree, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(about_x_deg * kRadiansPerDegree, Eigen::Vector3d::UnitX()))
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
    // Spread over the whole view, corners included: intrinsics need them.
    const Eigen::Vector3d centre(sym(rng) * 0.6 * z, sym(rng) * 0.45 * z, z);
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
  throw InputError(
      "no board pose keeps the board (rig.squares_x, squares_y, square_size_m) inside both cameras at "
      "depthboard.min_depth_m..max_depth_m; widen the depths or shrink the board");
}

// Furniture standing in front of a wall snapshot at `wall_z`: a box rising
// from the bottom of the image (or from a side), within the sensor's range,
// so it reads as valid depth that planar cleanup has to reject.
Clutter SampleFurniture(cv::Size image, double wall_z, double min_depth_m, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0, 1);
  const int w = static_cast<int>((0.15 + 0.25 * unit(rng)) * image.width);
  const int h = static_cast<int>((0.2 + 0.3 * unit(rng)) * image.height);
  const int x = static_cast<int>(unit(rng) * (image.width - w));
  const double z = std::max(min_depth_m + 0.05, wall_z * (0.55 + 0.3 * unit(rng)));
  return Clutter{cv::Rect(x, image.height - h, w, h), std::min(z, wall_z - 0.1)};
}

void Apply(CameraModel& camera, const CameraOverride& o) {
  if (o.intrinsics)
    std::tie(camera.fx, camera.fy, camera.cx, camera.cy) =
        std::tuple((*o.intrinsics)[0], (*o.intrinsics)[1], (*o.intrinsics)[2], (*o.intrinsics)[3]);
  if (o.distortion) camera.distortion = *o.distortion;
}

}  // namespace

SensorOptics OpticsFor(const Scenario& s) {
  SensorOptics optics = OpticsByName(s.optics);
  Apply(optics.colour, s.colour_camera);
  Apply(optics.ir, s.ir_camera);
  if (s.colour_from_ir_m) optics.colour_from_ir.translation() = Eigen::Vector3d::Map(s.colour_from_ir_m->data());
  if (s.colour_from_ir_rotation_deg) {
    const Eigen::Vector3d rotation = Eigen::Vector3d::Map(s.colour_from_ir_rotation_deg->data()) * kRadiansPerDegree;
    optics.colour_from_ir.linear() = rotation.norm() > 0
                                         ? Eigen::AngleAxisd(rotation.norm(), rotation.normalized()).toRotationMatrix()
                                         : Eigen::Matrix3d::Identity();
  }
  if (s.projector_in_ir_m) optics.projector_in_ir = Eigen::Vector3d::Map(s.projector_in_ir_m->data());
  return optics;
}

SessionSimulator::SessionSimulator(const Scenario& scenario) : scenario_(scenario) {
  const SensorOptics optics = OpticsFor(scenario);
  effects_ = BuildSimEffects(scenario.effects, "effects", {scenario.seed, optics.ir.size.width, optics.ir.size.height});
  std::vector<const SimEffect*> effect_pointers;
  for (const auto& e : effects_) effect_pointers.push_back(e.get());
  renderer_ = std::make_unique<SceneRenderer>(optics, scenario, effect_pointers);

  std::mt19937_64 rng(scenario.seed);
  const double frame_period = 1.0 / scenario.frame_rate_hz;
  double time = 0;
  const auto add_frames = [&](SimRecording which, int pose, int count, const TargetPose& target,
                              const std::vector<Clutter>& clutter) {
    auto& list = frames_[static_cast<int>(which)];
    for (int k = 0; k < count; ++k) {
      SimFrameSpec spec;
      spec.index = static_cast<int>(list.size());
      spec.context = {which, pose, time + k * frame_period, k * frame_period, scenario.seed};
      spec.colour_target = spec.depth_target = target;
      spec.clutter = clutter;
      for (const auto& e : effects_) e->MoveTarget(spec.context, spec.colour_target, spec.depth_target);
      list.push_back(spec);
    }
    time += scenario.depthboard.seconds_between_poses;
  };
  for (int pose = 0; pose < scenario.depthboard.poses; ++pose) {
    add_frames(SimRecording::kDepthboard, pose, scenario.depthboard.frames_per_pose,
               SampleBoardPose(scenario, optics, rng), {});
  }
  std::uniform_real_distribution<double> unit(0, 1);
  const PlanarSpec& p = scenario.planar;
  for (int snapshot = 0; snapshot < p.snapshots; ++snapshot) {
    const double z = p.snapshots == 1 ? p.min_depth_m
                                      : p.min_depth_m + (p.max_depth_m - p.min_depth_m) * snapshot / (p.snapshots - 1);
    TargetPose wall;
    wall.is_board = false;
    wall.ir_from_target.translation() = Eigen::Vector3d(0, 0, z);
    std::vector<Clutter> clutter;
    if (unit(rng) < p.clutter_probability) {
      // Something on the desk in front of the sensor, too near to read.
      const int w = 60 + static_cast<int>(unit(rng) * 120), h = 40 + static_cast<int>(unit(rng) * 80);
      const int x = static_cast<int>(unit(rng) * (optics.ir.size.width - w));
      clutter.push_back(Clutter{cv::Rect(x, optics.ir.size.height - h, w, h), 0.3});
    }
    // Drawn only when asked for, so older scenarios keep their random stream.
    if (p.furniture_probability > 0 && unit(rng) < p.furniture_probability) {
      clutter.push_back(SampleFurniture(optics.ir.size, z, scenario.depth.min_depth_m, rng));
    }
    add_frames(SimRecording::kPlanar, snapshot, p.frames_per_snapshot, wall, clutter);
  }
  for (int pose = 0; pose < scenario.ir_chessboard.poses; ++pose) {
    add_frames(SimRecording::kIrChessboard, pose, scenario.ir_chessboard.frames_per_pose,
               SampleBoardPose(scenario, optics, rng), {});
  }
}

namespace {

bool SameTarget(const TargetPose& a, const TargetPose& b) {
  return a.is_board == b.is_board && a.ir_from_target.matrix() == b.ir_from_target.matrix();
}

// Whether two frames see the same scene (an effect may move the target
// between the frames of a pose).
bool SameScene(const SimFrameSpec& a, const SimFrameSpec& b) {
  if (!SameTarget(a.colour_target, b.colour_target) || !SameTarget(a.depth_target, b.depth_target)) return false;
  return std::equal(a.clutter.begin(), a.clutter.end(), b.clutter.begin(), b.clutter.end(),
                    [](const Clutter& x, const Clutter& y) { return x.region == y.region && x.z_m == y.z_m; });
}

}  // namespace

std::shared_ptr<const SessionSimulator::StillScene> SessionSimulator::StillSceneOf(SimRecording which,
                                                                                   const SimFrameSpec& spec) const {
  auto& last = last_still_[static_cast<int>(which)];
  {
    std::lock_guard lock(still_mutex_);
    if (last && SameScene(last->spec, spec)) return last;
  }
  // Rendered outside the lock: the renderer runs parallel loops.
  auto still = std::make_shared<StillScene>();
  still->spec = spec;
  if (which == SimRecording::kIrChessboard) {
    still->clean_grey = renderer_->CleanInfrared(spec.colour_target);
  } else {
    still->truth = renderer_->TrueDepth(spec.depth_target, spec.clutter);
    still->clean_grey = renderer_->CleanColour(spec.colour_target);
  }
  std::lock_guard lock(still_mutex_);
  last = still;
  return still;
}

SimFrame SessionSimulator::Render(SimRecording which, const SimFrameSpec& spec) const {
  std::seed_seq seq{scenario_.seed, static_cast<std::uint64_t>(which), static_cast<std::uint64_t>(spec.index)};
  std::mt19937_64 rng(seq);
  const auto still = StillSceneOf(which, spec);
  SimFrame frame;
  if (which == SimRecording::kIrChessboard) {
    frame.ir = renderer_->Infrared(still->clean_grey, rng);
    return frame;
  }
  frame.raw_depth = renderer_->RawFromDepth(still->truth, spec.context, rng);
  frame.colour_rgb = renderer_->Colour(still->clean_grey, rng);
  return frame;
}

}  // namespace speckle::sim
