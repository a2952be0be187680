#pragma once
// A named step of run-pipeline: the depth camera from the depthboard's
// outlines, coarse to fine, for sessions that give no depth intrinsics and
// hold no IR chessboard recording (what real recordings are).
//
//   1. coarse: every outline found with gates widened by how far the nominal
//      camera may be off (the graph's quad node did this already);
//   2. calibrate: the depth camera and the extrinsics from those outlines;
//   3. fine: every outline found again with gates from the fitted camera,
//      narrowed to its uncertainty, and the camera fitted once more; again
//      while each pass finds more outlines (a camera far from nominal, such
//      as wide-angle optics, is found from the few outlines the first gates
//      caught, and its distortion from more).
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/pipeline_options.h"
#include "pipeline/raw_depth.h"
#include "stages/depthboard_quad.h"
#include "stages/outline_calibration.h"

namespace speckle {

// One board frame as the step sees it.
struct OutlineFrame {
  Eigen::Isometry3d colour_from_board = Eigen::Isometry3d::Identity();
  Eigen::Vector3d board_velocity = Eigen::Vector3d::Zero();
  // Finds this frame's outline where the given camera (with its standard
  // deviations) and extrinsics predict it, gated by how far that may be off.
  std::function<StageResult<DepthboardQuad>(const CameraIntrinsics&, const Eigen::Isometry3d&)> find_outline;
  std::optional<DepthboardQuad> quad;              // the coarse outline, when found
  const RawDepth* raw = nullptr;                   // the frame's raw depth image, for its board pixels
  const ChessboardDetection* detection = nullptr;  // the colour corners its pose came from
};

// Board pixels (u, v, raw) inside an outline, kept `inset_px` from its
// sides (mixed pixels), every `stride` pixels, that hold a reading.
std::vector<Eigen::Vector3d> BoardPixels(const cv::Mat& raw, const DepthboardQuad& quad, double inset_px, int stride,
                                         const DepthReading& reading);

struct DepthCameraStepResult {
  CameraIntrinsics depth;
  ExtrinsicsResult extrinsics;
  std::vector<ExtrinsicsView> views;               // what the camera was fitted to
  std::vector<StageResult<DepthboardQuad>> quads;  // the fine outlines, one per frame
  std::optional<std::string> not_fitted;           // why the nominal camera was kept
  std::optional<std::string> loosely_pinned;       // fitted, but too uncertain to trust: what to record
};

// How far (px) a camera's projection of `corners` may be off, from its
// standard deviations: three sigma of the principal point, and of the focal
// length and each distortion term at the corner farthest from the centre.
double PredictionUncertaintyPx(const CameraIntrinsics& camera, const std::array<Eigen::Vector2d, 4>& corners);

// `colour` gave the board poses: its uncertainty moves them all alike, so the
// depth camera's standard deviations include it (see AddColourCameraUncertainty).
// `reading` is the raw images' units.
DepthCameraStepResult CalibrateDepthCameraFromOutlines(const ExtrinsicsOptions& options, const DepthReading& reading,
                                                       const BoardGeometry& board, const CameraIntrinsics& colour,
                                                       const CameraIntrinsics& nominal,
                                                       const Eigen::Isometry3d& initial_depth_from_colour,
                                                       std::vector<OutlineFrame>& frames);

// Says when a fitted depth camera is known too loosely to trust (standard
// deviations over the options' limits), from `what`, and what to record.
std::optional<std::string> LooselyPinned(const ExtrinsicsOptions& options, const CameraIntrinsics& camera,
                                         const std::string& what);

// A frame's outline: in its own raw image, or in the median of its still
// pose's frames when more than one is given; its sides straight once
// undistorted through `camera`, and not cut by `dark_border` (see
// DepthboardQuadInput).
StageResult<DepthboardQuad> FindOutline(const PipelineOptions& options, const std::vector<RawDepth>& still_frames,
                                        const RawDepth& raw, const std::array<Eigen::Vector2d, 4>& predicted,
                                        double uncertainty_px, const CameraIntrinsics* camera,
                                        const cv::Mat* dark_border);

}  // namespace speckle
