#pragma once
// Stage 5: each projected board point's raw value (a robust local estimate;
// invalid and edge pixels rejected) paired with that point's depth from the
// colour pose, moved into the depth camera's frame, with its covariates.
#include "stages/depth_pose.h"
#include "stages/records.h"

namespace speckle {

struct PairingOptions {
  int window_radius = 1;           // 3x3 window for the local median
  double max_window_spread_raw = 8;  // wider spread: an edge, not a surface
};

struct PairingInput {
  int frame = 0;
  int pose = 0;
  double time_s = 0;
  double motion_px = 0;
  const cv::Mat& raw;
  const BoardInDepth& board_in_depth;
  const CameraCalibration& cameras;
  Eigen::Isometry3d colour_from_board;
};

// Rejects the frame only when no point could be paired.
StageResult<std::vector<PairedSample>> RunPairing(const PairingOptions& options, const PairingInput& input);

}  // namespace speckle
