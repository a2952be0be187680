#pragma once
// A named step of the calibration graph, its second barrier: once every
// board frame's outline (or board region) is in, the colour-to-depth
// extrinsics are fitted, in one of three ways:
//   - boards larger than their chessboard: the depth camera, extrinsics and
//     depth model jointly from the board planes (Herrera et al.), which
//     pairs their samples too;
//   - no depth camera given: the depth camera from the outlines, coarse to
//     fine (pipeline/steps/depth_camera_step.h);
//   - a depth camera given: the extrinsics alone, from the outlines;
//   - held (check): none; the outlines are kept as views, and board-plane
//     frames are paired with the held cameras.
#include <optional>
#include <string>
#include <vector>

#include "pipeline/frame_work.h"
#include "pipeline/pipeline_options.h"

namespace speckle {

enum class ExtrinsicsMode { kBoardPlanes, kDepthCameraFromOutlines, kOutlines, kHeld };

struct ExtrinsicsStepResult {
  CameraCalibration cameras;
  std::vector<ExtrinsicsView> views;  // what the extrinsics were fitted to
  // Why the depth camera could not come from the outlines: the run stops
  // once the graph is drained (a nominal camera would be a silent guess).
  std::optional<std::string> depth_camera_failure;
};

// `frames`: every board and planar frame, in any order. Board frames get
// their final outlines (and in board-plane mode their samples) or
// rejections; outlines are found again outside `dark_border`.
ExtrinsicsStepResult FitExtrinsics(const PipelineOptions& options, const BoardGeometry& board, ExtrinsicsMode mode,
                                   const CameraCalibration& cameras, const cv::Mat& dark_border,
                                   std::vector<Frame>& frames);

}  // namespace speckle
