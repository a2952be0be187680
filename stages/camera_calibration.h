#pragma once
// Stage 2: camera intrinsics from chessboard views, and board poses (the
// colour -> depth extrinsics are in stages/outline_calibration.h).
#include <optional>
#include <string>
#include <vector>

#include "stages/outline_calibration.h"
#include "stages/records.h"

namespace speckle {

struct IntrinsicsOptions {
  int max_views = 40;  // evenly spread over the detections given
  int min_views = 4;
  bool fix_k3 = false;  // k3 is poorly constrained with few, central views
  // False, naming the first broken rule's field in *why (schemas/option_check.h).
  bool IsValid(std::string* why) const;
};

// Throws InputError when fewer than min_views detections are given.
CameraIntrinsics RunIntrinsicsCalibration(const IntrinsicsOptions& options, const BoardGeometry& board,
                                          const std::vector<ChessboardDetection>& views);

// Board pose in a camera from its detected interior corners (solvePnP).
Eigen::Isometry3d BoardPose(const CameraIntrinsics& camera, const BoardGeometry& board,
                            const ChessboardDetection& detection);

// The pose's covariance, sigma^2 (J^T J)^-1, for a small rotation w and
// translation dt applied in the camera frame (pose' = (exp(w) R, t + dt)),
// sigma^2 the corners' reprojection variance about that pose (2N - 6 degrees
// of freedom), plus the spread of the poses the detection's other
// refinements give. What the true depths of the pose's board points inherit.
using PoseCovariance = Eigen::Matrix<double, 6, 6>;
PoseCovariance BoardPoseCovariance(const CameraIntrinsics& camera, const BoardGeometry& board,
                                   const ChessboardDetection& detection, const Eigen::Isometry3d& camera_from_board);

}  // namespace speckle
