#include "pipeline/steps/extrinsics_step.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>

#include "pipeline/steps/depth_camera_step.h"

namespace speckle {
namespace {

void FitBoardPlanes(const PipelineOptions& options, std::vector<Frame>& frames, ExtrinsicsStepResult& out) {
  std::vector<PlaneObservation> observations;
  std::vector<Frame> observed;
  for (const Frame& f : frames) {
    if (!f->IsBoard() || f->rejection || !f->region) continue;
    observations.push_back({f->index, f->pose, f->time_s, f->colour_from_board, *f->region});
    observed.push_back(f);
  }
  auto joint =
      RunJointPlaneCalibration(options.joint_plane, observations, out.cameras.depth, out.cameras.depth_from_colour);
  if (!Accepted(joint)) {
    for (const Frame& f : observed) f->rejection = std::get<Rejection>(joint);
    return;
  }
  auto& j = std::get<JointPlaneResult>(joint);
  AddJointPlaneUncertainty(options.joint_plane, observations, j);
  j.depth.views = static_cast<int>(observations.size());
  if (auto loose = LooselyPinned(options.extrinsics, j.depth, "the board planes")) {
    out.cameras.depth_intrinsics_warning = *loose;
    // The joint calibration judges its own camera again (pipeline/joint_cameras.cc).
    if (options.joint.enabled)
      spdlog::info("{}; the joint calibration refines it next", *loose);
    else
      spdlog::warn("{}", *loose);
  }
  out.cameras.depth = j.depth;
  out.cameras.depth_intrinsics_source = "joint_board_planes";
  out.cameras.depth_from_colour = j.depth_from_colour;
  out.cameras.extrinsics_views = static_cast<int>(observations.size());
  out.cameras.extrinsics_rms_px = 0;  // no outlines: written as not determined
  out.cameras.extrinsics_translation_sigma_m = j.translation_sigma_m;
  spdlog::info(
      "board planes: {} pixels from {} poses, {:.3f} raw rms; depth camera fx {:.1f} fy {:.1f} cx {:.1f} cy {:.1f}",
      j.pixels, observations.size(), j.rms_raw, j.depth.camera_matrix(0, 0), j.depth.camera_matrix(1, 1),
      j.depth.camera_matrix(0, 2), j.depth.camera_matrix(1, 2));
  const auto perturbations = JointPlanePerturbations(observations, j);
  std::size_t first = 0;  // observation i's samples in the perturbations
  for (std::size_t i = 0; i < observed.size(); ++i) {
    observed[i]->samples = PlaneSamples({observations[i]}, j.depth, j.depth_from_colour);
    const auto end = first + observed[i]->samples.size();
    for (const auto& moved : perturbations)
      observed[i]->plane_perturbations.emplace_back(moved.begin() + static_cast<std::ptrdiff_t>(first),
                                                    moved.begin() + static_cast<std::ptrdiff_t>(end));
    first = end;
  }
}

// The board frames with an outline, and their outlines as views.
struct Outlined {
  std::vector<Frame> frames;
  std::vector<ExtrinsicsView> views;
};

Outlined OutlineViews(const std::vector<Frame>& frames) {
  Outlined out;
  for (const Frame& f : frames) {
    if (!f->IsBoard() || f->rejection || !f->quad) continue;
    out.frames.push_back(f);
    out.views.push_back({f->colour_from_board, *f->quad, f->board_velocity, {}});
  }
  return out;
}

// A frame whose depth outline the fitted extrinsics cannot put where the
// colour pose says is not paired: its quad is not the board's whole outline
// (cut by a border the session never read well enough to see, or covered),
// or its depth image is not of its colour image's moment, and the depth pose
// from it would read raw values away from the board points whose depths
// they are paired with.
void RejectDisagreeingOutlines(const PipelineOptions& options, const BoardGeometry& board, const ExtrinsicsResult& e,
                               const Outlined& outlined, const CameraIntrinsics& depth) {
  for (std::size_t i = 0; i < outlined.frames.size(); ++i) {
    const double error = OutlineErrorPx(board, depth, e, outlined.views[i]);
    if (error < options.extrinsics.outlier_px) continue;
    outlined.frames[i]->rejection = Rejection{
        "extrinsics", fmt::format("its depth outline is {:.1f} px from where the colour pose and the fitted extrinsics "
                                  "put it (the board is cut, covered or moved in the depth image)",
                                  error)};
  }
}

// The extrinsics fitted to the frames' outlines with the depth camera held,
// or as the depth camera step fitted them (`fitted`).
void AdoptExtrinsics(const PipelineOptions& options, const BoardGeometry& board, const std::vector<Frame>& frames,
                     std::optional<ExtrinsicsResult> fitted, ExtrinsicsStepResult& out) {
  Outlined outlined = OutlineViews(frames);
  out.views = outlined.views;
  if (!fitted && out.views.size() < 3) return;
  const ExtrinsicsResult e =
      fitted ? std::move(*fitted)
             : RunExtrinsicsCalibration(options.extrinsics, options.reading, board, out.cameras.depth, out.views,
                                        out.cameras.depth_from_colour);
  out.cameras.depth_from_colour = e.depth_from_colour;
  out.cameras.extrinsics_rms_px = e.rms_px;
  out.cameras.extrinsics_views = e.views;
  out.cameras.extrinsics_translation_sigma_m = e.translation_sigma_m;
  out.cameras.depth_delay_s = e.delay_s;
  out.cameras.depth_edge_offset_px = e.edge_offset_px;
  if (e.delay_s) spdlog::info("the board moved: depth images lag colour by {:.1f} ms", 1e3 * *e.delay_s);
  RejectDisagreeingOutlines(options, board, e, outlined, out.cameras.depth);
}

// Nothing fitted: each outline is a view (where check measures the
// registration), and each board region is paired with the held cameras.
void HoldCameras(const std::vector<Frame>& frames, ExtrinsicsStepResult& out) {
  out.views = OutlineViews(frames).views;
  for (const Frame& f : frames) {
    if (!f->IsBoard() || f->rejection || !f->region) continue;
    const PlaneObservation seen{f->index, f->pose, f->time_s, f->colour_from_board, *f->region};
    f->samples = PlaneSamples({seen}, out.cameras.depth, out.cameras.depth_from_colour);
  }
}

// Each board frame's outline is found again where the fitted camera puts it.
void CalibrateDepthCamera(const PipelineOptions& options, const BoardGeometry& board, const cv::Mat& dark_border,
                          std::vector<Frame>& frames, ExtrinsicsStepResult& out) {
  const auto outline = OutlineCorners(board);
  std::vector<Frame> searched;
  std::vector<OutlineFrame> outline_frames;
  for (const Frame& f : frames) {
    if (!f->IsBoard() || !f->detection || (f->rejection && f->rejection->stage != "depthboard_quad")) continue;
    searched.push_back(f);
    OutlineFrame& o = outline_frames.emplace_back();
    o.colour_from_board = f->colour_from_board;
    o.board_velocity = f->board_velocity;
    o.quad = f->rejection ? std::nullopt : f->quad;
    o.raw = &f->raw;
    o.detection = &*f->detection;
    o.find_outline = [&, frame = f.get()](const CameraIntrinsics& depth, const Eigen::Isometry3d& depth_from_colour) {
      std::array<Eigen::Vector2d, 4> predicted;
      for (int k = 0; k < 4; ++k)
        predicted[k] = depth.Project(depth_from_colour * frame->colour_from_board * outline[k]);
      const double uncertainty = std::min(options.nominal_prediction_px, PredictionUncertaintyPx(depth, predicted));
      return FindOutline(options, frame->still_neighbours, frame->raw, predicted, uncertainty, &depth, &dark_border);
    };
  }
  ExtrinsicsOptions extrinsics = options.extrinsics;
  const bool from_ir = out.cameras.depth_intrinsics_source == "ir_chessboard";
  if (from_ir) {
    // The focal lengths are refined, held to the IR values by their sigmas:
    // every board's distance comes from the colour camera, and a depth camera
    // whose scale follows it pairs consistent depths. The principal point
    // and the lens stay the IR chessboard's (sigma 0 holds them): the
    // outlines would move them to take up the depth image's shift from the
    // IR image (depth_grid_offset), which the diagnosis is there to find.
    extrinsics.depth_prior = out.cameras.depth;
    std::fill(extrinsics.depth_prior->stddev.begin() + 2, extrinsics.depth_prior->stddev.end(), 0.0);
  }
  DepthCameraStepResult step =
      CalibrateDepthCameraFromOutlines(extrinsics, options.reading, board, out.cameras.colour, out.cameras.depth,
                                       out.cameras.depth_from_colour, outline_frames);
  for (std::size_t i = 0; i < searched.size(); ++i) {
    searched[i]->still_neighbours.clear();
    searched[i]->rejection.reset();
    searched[i]->quad.reset();
    Take(*searched[i], std::move(step.quads[i]), &searched[i]->quad);
  }
  if (step.not_fitted && from_ir) {
    // The IR chessboard's camera stands on its own: keep it, and say why it
    // was not refined.
    spdlog::warn("the depthboard outlines did not refine the IR chessboard's depth camera: {}", *step.not_fitted);
    AdoptExtrinsics(options, board, frames, std::nullopt, out);
    return;
  }
  if (step.not_fitted) {
    out.depth_camera_failure = *step.not_fitted;
    return;
  }
  const CameraIntrinsics ir = out.cameras.depth;
  out.cameras.depth = step.depth;
  if (from_ir) {
    // What the fit held keeps the IR chessboard's standard deviation.
    for (std::size_t i = 2; i < ir.stddev.size(); ++i)
      out.cameras.depth.stddev[i] = std::max(out.cameras.depth.stddev[i], ir.stddev[i]);
  }
  const int ir_views = from_ir ? ir.views : 0;
  out.cameras.depth.views += ir_views;  // refined jointly: fitted from the IR chessboards and the outlines
  out.cameras.depth_intrinsics_source = from_ir ? "ir_chessboard+depth_outlines" : "depth_outlines";
  if (step.loosely_pinned) {
    out.cameras.depth_intrinsics_warning = *step.loosely_pinned;
    spdlog::warn("{}", *step.loosely_pinned);
  }
  AdoptExtrinsics(options, board, frames, std::move(step.extrinsics), out);
}

}  // namespace

ExtrinsicsStepResult FitExtrinsics(const PipelineOptions& options, const BoardGeometry& board, ExtrinsicsMode mode,
                                   const CameraCalibration& cameras, const cv::Mat& dark_border,
                                   std::vector<Frame>& frames) {
  // Frames arrive in whatever order the graph finished them: fit from them
  // in recording order, so that a run is reproducible.
  std::sort(frames.begin(), frames.end(), [](const Frame& a, const Frame& b) {
    return std::make_pair(a->recording, a->index) < std::make_pair(b->recording, b->index);
  });
  ExtrinsicsStepResult out;
  out.cameras = cameras;
  switch (mode) {
    case ExtrinsicsMode::kBoardPlanes:
      FitBoardPlanes(options, frames, out);
      break;
    case ExtrinsicsMode::kDepthCameraFromOutlines:
      CalibrateDepthCamera(options, board, dark_border, frames, out);
      break;
    case ExtrinsicsMode::kOutlines:
      AdoptExtrinsics(options, board, frames, std::nullopt, out);
      break;
    case ExtrinsicsMode::kHeld:
      HoldCameras(frames, out);
      break;
  }
  return out;
}

}  // namespace speckle
