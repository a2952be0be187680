#pragma once
// Stage 4: the board's pose in the depth camera from its outline quad
// (solvePnP on the four outer corners), and the board points whose raw
// values will be paired, projected into the depth image.
#include "stages/records.h"

namespace speckle {

struct BoardPoint {
  Eigen::Vector3d in_board;  // metres, z = 0
  Eigen::Vector2d pixel;     // in the depth image
  SamplePoint kind = SamplePoint::kInteriorCorner;
  double albedo = 0.5;  // 0 dark square, 1 light square, 0.5 a corner
};

struct BoardInDepth {
  Eigen::Isometry3d depth_from_board = Eigen::Isometry3d::Identity();
  std::vector<BoardPoint> points;
};

struct DepthPoseOptions {
  // Also pair the centre of every square: a corner mixes dark and light
  // squares, a centre shows one albedo.
  bool square_centres = true;
};

StageResult<BoardInDepth> RunDepthPose(const DepthPoseOptions& options, const BoardGeometry& board,
                                       const CameraIntrinsics& depth, const DepthboardQuad& quad);

}  // namespace speckle
