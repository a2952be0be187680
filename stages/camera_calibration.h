#pragma once
// Stage 2: camera intrinsics from chessboard views, and the colour -> depth
// extrinsics from board poses seen by both cameras.
#include <optional>
#include <vector>

#include "stages/records.h"

namespace speckle {

struct IntrinsicsOptions {
  int max_views = 40;   // evenly spread over the detections given
  int min_views = 4;
  bool fix_k3 = false;  // k3 is poorly constrained with few, central views
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
// of freedom). What the true depths of the pose's board points inherit.
using PoseCovariance = Eigen::Matrix<double, 6, 6>;
PoseCovariance BoardPoseCovariance(const CameraIntrinsics& camera, const BoardGeometry& board,
                                   const ChessboardDetection& detection, const Eigen::Isometry3d& camera_from_board);

// One board pose seen by both cameras: the colour pose and the depth quad.
struct ExtrinsicsView {
  Eigen::Isometry3d colour_from_board;
  DepthboardQuad quad;
  Eigen::Vector3d board_velocity = Eigen::Vector3d::Zero();  // colour-camera m/s (see FrameWork)
};

struct ExtrinsicsOptions {
  double outlier_px = 3.0;  // views whose outline reprojects worse are dropped after a first fit
  // The depth image's delay after the colour image is fitted with the
  // extrinsics when the views' median board speed reaches this: a moving
  // board's depth outline lags its colour pose, which a rotation would
  // otherwise absorb.
  double min_speed_for_delay_m_s = 0.05;
};

// depth_from_colour minimising the reprojection of the board's outline corners
// (from each colour pose) onto the depth quads, over all views (Ceres).
// Returns the transform, its RMS in depth pixels and the views used.
struct ExtrinsicsResult {
  Eigen::Isometry3d depth_from_colour = Eigen::Isometry3d::Identity();
  double rms_px = 0;
  int views = 0;
  // Standard deviation of the translation (metres), from the fit's covariance
  // scaled by its residual variance.
  Eigen::Vector3d translation_sigma_m = Eigen::Vector3d::Zero();
  std::optional<double> delay_s;  // fitted when the board moved (see ExtrinsicsOptions)
};
ExtrinsicsResult RunExtrinsicsCalibration(const ExtrinsicsOptions& options, const BoardGeometry& board,
                                          const CameraIntrinsics& depth, const std::vector<ExtrinsicsView>& views,
                                          const Eigen::Isometry3d& initial);

// The board's outline corners (0,0), (W,0), (W,H), (0,H) in board coordinates.
std::array<Eigen::Vector3d, 4> OutlineCorners(const BoardGeometry& board);

}  // namespace speckle
