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
};

struct BoardInDepth {
  Eigen::Isometry3d depth_from_board = Eigen::Isometry3d::Identity();
  std::vector<BoardPoint> points;
  BoardGeometry board;  // whose squares' albedo the pairing window sees
};

// The IR albedo the board shows at a point on it (metres, board frame): 0 on
// a dark square, 1 on a light one, 0.5 off the chessboard (unknown).
double BoardAlbedo(const BoardGeometry& board, const Eigen::Vector2d& in_board);

struct DepthPoseOptions {
  // Also pair the centre of every square: a corner mixes dark and light
  // squares, a centre shows one albedo.
  bool square_centres = true;
};

StageResult<BoardInDepth> RunDepthPose(const DepthPoseOptions& options, const BoardGeometry& board,
                                       const CameraIntrinsics& depth, const DepthboardQuad& quad);

}  // namespace speckle
