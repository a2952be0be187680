#pragma once
// The calibration graph's per-frame steps (pipeline/calibration_graph.cc),
// each run on many frames at once: what one frame needs done between the
// barriers. A frame that fails a step carries its Rejection on.
#include "pipeline/frame_work.h"
#include "pipeline/pipeline_options.h"
#include "pipeline/stage_clocks.h"

namespace speckle {

// What every step reads: the options, the board, and the clocks it adds to.
struct StepContext {
  const PipelineOptions& options;
  const BoardGeometry& board;
  StageClocks& clocks;
  // The session's dark border (stages/dark_border.h): known once the first
  // barrier has seen every frame, empty before.
  const cv::Mat& dark_border;
};

// The chessboard in each colour (or IR) frame of a batch of consecutive
// frames: tracked from the previous frame where it can be, else detected.
// Images no later step needs are released.
void DetectBoards(const StepContext& step, Batch& batch);

// A board frame's outline in its depth image (its quad, or for boards larger
// than their chessboard its region), gated where `cameras` put it.
// `uncertainty_px` widens the gate when the depth camera is not known yet.
void ExtractOutline(const StepContext& step, const CameraCalibration& cameras, bool plane_mode, double uncertainty_px,
                    FrameWork& frame);

// A board frame's depth pose from its quad, then its paired samples.
void PoseAndPair(const StepContext& step, const CameraCalibration& cameras, FrameWork& frame);

// A planar frame's flat-wall snapshot.
void CleanSnapshot(const StepContext& step, const CameraIntrinsics& depth, FrameWork& frame);

}  // namespace speckle
