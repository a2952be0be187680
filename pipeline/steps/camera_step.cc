#include "pipeline/steps/camera_step.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for_each.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>

#include "pipeline/steps/board_poses.h"
#include "schemas/errors.h"

namespace speckle {
namespace {

CameraIntrinsics FromSession(const KnownIntrinsics& k) {
  CameraIntrinsics c;
  c.image_size = cv::Size(k.width, k.height);
  c.camera_matrix = cv::Matx33d(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  c.distortion = k.distortion;
  c.stddev = k.stddev;  // zero unless the session states them
  return c;
}

// Given or nominal intrinsics were fitted to no views: said so, not "rms
// 0.000 px over 0 views", which reads as a perfect fit.
std::string Describe(const CameraIntrinsics& c) {
  return fmt::format("fx {:.1f} fy {:.1f} cx {:.1f} cy {:.1f} k {:.3f} {:.3f} {:.4f} {:.4f} {:.3f}, {}",
                     c.camera_matrix(0, 0), c.camera_matrix(1, 1), c.camera_matrix(0, 2), c.camera_matrix(1, 2),
                     c.distortion[0], c.distortion[1], c.distortion[2], c.distortion[3], c.distortion[4],
                     c.views > 0 ? fmt::format("rms {:.3f} px over {} views", c.rms_reprojection_px, c.views)
                                 : std::string("not fitted to any view"));
}

// One view per still pose calibrates the colour camera.
std::vector<ChessboardDetection> PoseViews(const std::vector<Frame>& boards) {
  std::vector<ChessboardDetection> views;
  int last_pose = -1;
  for (const Frame& b : boards) {
    if (b->detection && b->pose != last_pose) views.push_back(*b->detection);
    if (b->detection) last_pose = b->pose;
  }
  return views;
}

// The depth camera before the outlines: the session's, the IR chessboard's
// or nominal (for the last two, `depth_camera_from_outlines` says the
// extrinsics step fits it: from the IR chessboard's as a prior, or from none).
void ChooseDepthCamera(const CameraStepInput& in, const std::vector<ChessboardDetection>& ir_views,
                       CameraStepResult& out) {
  if (in.manifest.depth_intrinsics) {
    out.cameras.depth = FromSession(*in.manifest.depth_intrinsics);
    out.cameras.depth_intrinsics_source = "session";
  } else if (ir_views.size() >= static_cast<std::size_t>(in.options.intrinsics.min_views)) {
    out.cameras.depth = RunIntrinsicsCalibration(in.options.intrinsics, in.board, ir_views);
    out.cameras.depth_intrinsics_source = "ir_chessboard";
    // The extrinsics step refines it with the depthboard outlines, held to
    // these values by their sigmas (issue 17: "refine jointly").
    out.depth_camera_from_outlines = !in.plane_mode;
  } else {
    out.cameras.depth = NominalDepthCamera(in.depth_size);
    out.cameras.depth_intrinsics_source = "nominal";
    out.depth_camera_from_outlines = !in.plane_mode;
  }
}

}  // namespace

void AttachSessionPriors(const SessionManifest& manifest, CameraCalibration& cameras) {
  if (manifest.colour_intrinsics && manifest.colour_intrinsics->HasPrior())
    cameras.colour_prior = FromSession(*manifest.colour_intrinsics);
  if (manifest.depth_intrinsics && manifest.depth_intrinsics->HasPrior())
    cameras.depth_prior = FromSession(*manifest.depth_intrinsics);
}

CameraIntrinsics NominalDepthCamera(cv::Size size) {
  CameraIntrinsics c;
  c.image_size = size;
  c.camera_matrix = cv::Matx33d(580, 0, (size.width - 1) / 2.0, 0, 580, (size.height - 1) / 2.0, 0, 0, 1);
  return c;
}

namespace {

// Every board frame's colour pose from the colour camera, and its motion.
void PoseBoards(const CameraStepInput& in, const CameraIntrinsics& colour, std::vector<Frame>& boards) {
  tbb::parallel_for_each(boards.begin(), boards.end(), [&](const Frame& b) {
    Guarded(*b, "camera_calibration", [&] {
      b->colour_from_board = BoardPose(colour, in.board, *b->detection);
      b->colour_pose_covariance = BoardPoseCovariance(colour, in.board, *b->detection, b->colour_from_board);
    });
  });
  AssignBoardMotion(boards, Eigen::Vector3d(in.board.Width() / 2, in.board.Height() / 2, 0),
                    in.options.max_velocity_gap_s);
}

}  // namespace

CameraStepResult CalibrateCameras(const CameraStepInput& in, std::vector<Frame>& frames) {
  // Frames arrive in whatever order the graph finished them: calibrate from
  // them in recording order, so that a run is reproducible.
  std::sort(frames.begin(), frames.end(), [](const Frame& a, const Frame& b) { return a->index < b->index; });
  std::vector<Frame> boards;
  std::vector<ChessboardDetection> ir_views;
  for (const Frame& f : frames) {
    if (f->IsBoard()) boards.push_back(f);
    if (f->recording == RecordingPurpose::kIrChessboard && f->detection) ir_views.push_back(*f->detection);
  }
  AssignPoses(boards, in.options.still_pose_motion_px, in.options.max_velocity_gap_s);
  GatherStillNeighbours(boards, in.options.still_frames_averaged);
  CameraStepResult out;
  if (in.options.held_cameras) {  // check: a calibration's cameras, nothing fitted
    out.cameras = *in.options.held_cameras;
    PoseBoards(in, out.cameras.colour, boards);
    return out;
  }
  std::optional<std::string> colour_failure;
  tbb::parallel_invoke(  // colour and IR intrinsics are independent
      [&] {
        if (in.manifest.colour_intrinsics) {
          out.cameras.colour = FromSession(*in.manifest.colour_intrinsics);
          return;
        }
        try {
          out.cameras.colour = RunIntrinsicsCalibration(in.options.intrinsics, in.board, PoseViews(boards));
        } catch (const InputError& e) {
          colour_failure = e.what();
        }
      },
      [&] { ChooseDepthCamera(in, ir_views, out); });
  AttachSessionPriors(in.manifest, out.cameras);
  if (colour_failure) {
    for (const Frame& b : boards)
      if (!b->rejection) b->rejection = Rejection{"camera_calibration", *colour_failure};
    return out;
  }
  spdlog::info("colour camera: {}", Describe(out.cameras.colour));
  spdlog::info("depth camera ({}): {}{}", out.cameras.depth_intrinsics_source, Describe(out.cameras.depth),
               out.depth_camera_from_outlines && out.cameras.depth_intrinsics_source == "nominal"
                   ? "; a start: the depthboard outlines fit it next"
                   : "");
  // Nominal extrinsics until the outlines refine them: the colour camera
  // sits about 2.5 cm beside the IR camera.
  out.cameras.depth_from_colour = Eigen::Isometry3d::Identity();
  out.cameras.depth_from_colour.translation() = Eigen::Vector3d(0.025, 0, 0);
  PoseBoards(in, out.cameras.colour, boards);
  return out;
}

}  // namespace speckle
