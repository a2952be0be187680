#pragma once
// Stage 5: each projected board point's raw value (a robust local estimate;
// invalid and edge pixels rejected) paired with that point's depth from the
// colour pose, moved into the depth camera's frame, with its covariates.
#include <string>

#include "stages/camera_calibration.h"
#include "stages/depth_pose.h"
#include "stages/records.h"

namespace speckle {

struct PairingOptions {
  // The raw value at a board point is a least-squares plane through the
  // (2r+1)^2 window around it, evaluated at the point's sub-pixel position:
  // it averages noise and quantization and follows a tilted board's slope.
  int window_radius = 2;
  double max_plane_rms_raw = 2.5;  // worse: the window straddles an edge or holes
  // False, naming the first broken rule's field in *why (schemas/option_check.h).
  bool IsValid(std::string* why) const;
};

struct PairingInput {
  int frame = 0;
  int pose = 0;
  double time_s = 0;
  double motion_px = 0;
  Eigen::Vector2d velocity_px_s = Eigen::Vector2d::Zero();
  const cv::Mat& raw;
  const BoardInDepth& board_in_depth;
  const CameraCalibration& cameras;
  Eigen::Isometry3d colour_from_board;
  PoseCovariance colour_pose_covariance = PoseCovariance::Zero();
  DepthReading reading{};  // raw's units: which values are no reading
};

// Rejects the frame only when no point could be paired.
StageResult<std::vector<PairedSample>> RunPairing(const PairingOptions& options, const PairingInput& input);

}  // namespace speckle
