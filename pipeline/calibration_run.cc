#include "pipeline/calibration_run.h"

#include <stdexcept>

#include <tbb/parallel_for.h>

#include <chrono>
#include <optional>

#include <spdlog/spdlog.h>

#include "model/sensor_family.h"
#include "pipeline/graph_outcome.h"
#include "pipeline/joint_cameras.h"
#include "pipeline/steps/depth_camera_step.h"
#include "schemas/errors.h"
#include "stages/step_clock.h"

namespace speckle {

namespace {

double RelativeFocalSigma(const CameraIntrinsics& c) {
  return 0.5 * (c.stddev[0] / c.camera_matrix(0, 0) + c.stddev[1] / c.camera_matrix(1, 1));
}

// Every sample's true depth under a one-sigma change of each camera input.
DepthPerturbations CameraPerturbations(const PipelineResult& p, const PipelineOptions& options) {
  DepthPerturbations out;
  // The colour focal length scales every depth from a colour pose alike.
  const double colour = RelativeFocalSigma(p.cameras.colour);
  if (colour > 0) {
    std::vector<double>& depths = out.depths.emplace_back();
    for (const auto& s : p.samples) depths.push_back(s.depth_m * (1 + colour));
  }
  // The IR intrinsics move the extrinsics fitted through them: the focal
  // length chiefly along the axis, the principal point as a rotation that
  // tilts every depth. Each is moved by one sigma and the extrinsics refitted.
  // Nominal IR intrinsics are taken as uncertain by 2 % and 5 px.
  const bool nominal = p.cameras.depth_intrinsics_source == "nominal";
  const auto refit_with = [&](const CameraIntrinsics& moved_depth) {
    const ExtrinsicsResult moved = RunExtrinsicsCalibration(options.extrinsics, options.reading, p.board, moved_depth,
                                                            p.extrinsics_views, p.cameras.depth_from_colour);
    std::vector<double>& depths = out.depths.emplace_back();
    for (const auto& s : p.samples) depths.push_back((moved.depth_from_colour * s.in_colour).z());
  };
  if (p.extrinsics_views.size() >= 3) {
    const double ir = nominal ? 0.02 : RelativeFocalSigma(p.cameras.depth);
    if (ir > 0) {
      CameraIntrinsics longer = p.cameras.depth;
      longer.camera_matrix(0, 0) *= 1 + ir;
      longer.camera_matrix(1, 1) *= 1 + ir;
      refit_with(longer);
    }
    for (int axis : {0, 1}) {
      const double sigma_px = nominal ? 5.0 : p.cameras.depth.stddev[static_cast<std::size_t>(2 + axis)];
      if (!(sigma_px > 0)) continue;
      CameraIntrinsics shifted = p.cameras.depth;
      shifted.camera_matrix(axis, 2) += sigma_px;
      refit_with(shifted);
    }
  }
  // The extrinsics' own uncertainty along the depth axis offsets every depth.
  const double tz = p.cameras.extrinsics_translation_sigma_m.z();
  if (tz > 0 && p.plane_perturbations.empty()) {
    Eigen::Isometry3d moved = p.cameras.depth_from_colour;
    moved.translation().z() += tz;
    std::vector<double>& depths = out.depths.emplace_back();
    for (const auto& s : p.samples) depths.push_back((moved * s.in_colour).z());
  }
  // Last, not in the floor: the joint board-plane fit moved its depth camera
  // and extrinsics together, and with the depth model.
  out.in_floor = out.depths.size();
  out.depths.insert(out.depths.end(), p.plane_perturbations.begin(), p.plane_perturbations.end());
  return out;
}

// The cameras refined with every board frame's observations (see
// pipeline/joint_cameras.h), when they came from the data. Nothing when the
// joint fit is off, does not apply, or fails (said, and the separate steps'
// cameras kept).
std::optional<JointCameras> RefineCamerasJointly(const PipelineOptions& options, const ModelSpec& spec,
                                                 PipelineResult& p) {
  if (!options.joint.enabled || p.board_observations.empty()) return std::nullopt;
  auto joint = FitCamerasJointly({options.joint, options.extrinsics, p.board, p.cameras, spec, options.reading,
                                  p.board_observations, p.samples, options.diagnosis.folds, "the separate steps'", "",
                                  options.raw_rate});
  if (joint) {
    p.cameras = joint->cameras;
    p.samples = std::move(joint->samples);
  }
  return joint;
}

// The undistortion grid from the graph's flat-wall snapshots, timed as the
// graph's stages are.
void BuildUndistortionGrid(const PipelineOptions& options, PipelineResult& p) {
  if (!p.planar_recording) {
    p.grid_rejection = Rejection{"undistortion_grid", "the session has no planar recording"};
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  auto grid = RunUndistortionGridBuild(options.grid, p.snapshots);
  if (Accepted(grid)) {
    p.grid = std::move(std::get<UndistortionGrid>(grid));
  } else {
    p.grid_rejection = std::get<Rejection>(grid);
  }
  for (auto& t : p.timings) {
    if (t.stage != "undistortion_grid") continue;
    t.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ++t.calls;
  }
}

// Flat walls before and after undistortion, each wall corrected by a grid
// that never saw it.
void HoldOutWalls(const PipelineOptions& options, CalibrationRun& run) {
  const PipelineResult& p = run.pipeline;
  if (!p.grid || p.snapshots.size() < 3) return;
  const auto grids = RunUndistortionGridHoldOuts(options.grid, p.snapshots);
  std::vector<std::optional<WallFlatness>> held_out(p.snapshots.size());
  StepProgress progress("wall hold-out", static_cast<int>(p.snapshots.size()));
  tbb::parallel_for(std::size_t{0}, p.snapshots.size(), [&](std::size_t held) {
    const StepClock clock;
    progress.Done();
    if (!Accepted(grids[held])) return;
    const auto& g = std::get<UndistortionGrid>(grids[held]);
    const PlanarSnapshot& s = p.snapshots[held];
    // Scatter about the wall's truth (for a tilted wall, its own plane).
    std::vector<double> raw_off, corrected_off;
    for (const auto& px : s.inliers) {
      const double truth = s.TrueRaw(g.method, px.x, px.y);
      raw_off.push_back(px.raw - truth);
      corrected_off.push_back(g.Apply(px.raw, px.x, px.y) - truth);
    }
    held_out[held] = WallFlatness{s.frame, s.TrueRaw(g.method), Summarize(raw_off).sigma,
                                  Summarize(corrected_off).sigma, clock.Seconds()};
  });
  double before = 0, after = 0;
  for (const auto& wall : held_out) {
    if (!wall) continue;
    run.walls.push_back(*wall);
    before += wall->sigma_before, after += wall->sigma_after;
  }
  if (before > 0) run.wall_sigma_reduction = 1 - after / before;
}

}  // namespace

// The board's size by the depth's own scale against the rig's: a wrong
// square size otherwise passes into every depth, with a normal summary.
void WarnIfTheBoardIsNotItsStatedSize(const std::filesystem::path& session_dir, const PipelineResult& p) {
  if (!p.board_size_in_depth || !p.board_size_in_depth->OutsideFamily()) return;
  const BoardSizeInDepth& size = *p.board_size_in_depth;
  const bool larger = size.Ratio() > 1;
  spdlog::warn(
      "the depth sensor measures the board {:.0f} % {} than {}'s rig describes it ({:.3f} +- {:.3f} m against "
      "{:.3f} m, the square root of its area; {} x {} squares of {:.4f} m), by its own triangulation over {} "
      "board views with the family's {:.1f} cm projector baseline. Most likely rig.square_size_m is wrong (one "
      "square's side, in metres), and every depth fitted to this board is about {:.0f} % {}",
      100 * std::abs(size.Ratio() - 1), larger ? "larger" : "smaller", (session_dir / kSessionFileName).string(),
      size.measured_m, size.sigma_m, size.stated_m, p.board.squares_x, p.board.squares_y, p.board.square_size_m,
      size.views, 100 * model::kFamilyBaselineM, 100 * std::abs(1 - 1 / size.Ratio()), larger ? "short" : "long");
}

CalibrationRun RunCalibration(const std::filesystem::path& session_dir, const PipelineOptions& options,
                              const ModelSpec& spec) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("run-pipeline's options: " + why);
  const StepClock total_clock;
  CalibrationRun run;
  run.spec = spec;
  // The joint fit states the cameras' uncertainty from every observation, so
  // the outline step's refits for its own are left to a run without it.
  PipelineOptions graph_options = options;
  if (options.joint.enabled) graph_options.extrinsics.refit_for_sigmas = false;
  run.pipeline = RunCalibrationGraph(session_dir, graph_options);
  PipelineResult& p = run.pipeline;
  WarnIfTheBoardIsNotItsStatedSize(session_dir, p);
  p.samples = AssignRawRates(options.raw_rate, std::move(p.samples));
  BuildUndistortionGrid(options, p);
  if (p.samples.empty()) {
    std::map<std::string, int> reasons;
    for (const auto& f : p.frames)
      if (f.rejection) ++reasons[f.rejection->stage + ": " + f.rejection->reason];
    throw InputError(session_dir.string() + ": no depthboard frame could be paired, so there is nothing to fit" +
                     RejectionReasons(reasons));
  }
  const StepClock walls_clock;
  HoldOutWalls(options, run);
  run.seconds.wall_hold_outs = walls_clock.Seconds();
  // The walls' pixels have made the grid and its hold-outs; the fits do not
  // need them (42 MB at 32 snapshots, held through the fits before).
  for (auto& snapshot : p.snapshots) std::vector<PlanarPixel>().swap(snapshot.inliers);
  const StepClock perturbation_clock;
  auto joint = RefineCamerasJointly(p.options, spec, p);
  if (!joint && options.joint.enabled) {
    spdlog::warn(
        "without the joint fit, the separate steps run again with the refits that state their cameras' "
        "uncertainty");
    PipelineOptions separate = options;
    separate.joint.enabled = false;
    return RunCalibration(session_dir, separate, spec);
  }
  run.perturbations = joint ? std::move(joint->perturbations) : CameraPerturbations(p, p.options);
  run.seconds.camera_perturbations = perturbation_clock.Seconds();
  // The samples move into the lab (run.lab.samples), which keeps them.
  run.lab = RunModelLab({spec, std::move(p.samples), p.grid, run.perturbations, p.depth_units, session_dir.string(),
                         options.refit_tool, options.diagnosis, joint ? joint->judge : HeldOutJudge{}});
  run.seconds.total = total_clock.Seconds();
  return run;
}

}  // namespace speckle
