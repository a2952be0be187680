#include "stages/depth_pose.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "stages/camera_calibration.h"

namespace speckle {

StageResult<BoardInDepth> RunDepthPose(const DepthPoseOptions& options, const BoardGeometry& board,
                                       const CameraIntrinsics& depth, const DepthboardQuad& quad) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  const auto outline = OutlineCorners(board);
  for (int k = 0; k < 4; ++k) {
    object.emplace_back(outline[k].x(), outline[k].y(), 0);
    image.emplace_back(quad.corners_px[k].x(), quad.corners_px[k].y());
  }
  cv::Mat rvec, tvec;
  if (!cv::solvePnP(object, image, cv::Mat(depth.camera_matrix),
                    cv::Mat(1, 5, CV_64F, const_cast<double*>(depth.distortion.data())), rvec, tvec, false,
                    cv::SOLVEPNP_IPPE)) {
    return Rejection{"depth_pose", "solvePnP found no pose for the outline"};
  }
  cv::Mat rotation;
  cv::Rodrigues(rvec, rotation);
  BoardInDepth out;
  Eigen::Matrix3d r;
  Eigen::Vector3d t;
  cv::cv2eigen(rotation, r);
  cv::cv2eigen(tvec, t);
  out.depth_from_board.linear() = r;
  out.depth_from_board.translation() = t;
  if (t.z() <= 0) return Rejection{"depth_pose", "the outline's pose puts the board behind the camera"};

  const double s = board.square_size_m;
  const auto add = [&](double bx, double by, SamplePoint kind) {
    const Eigen::Vector3d p(bx, by, 0);
    out.points.push_back({p, depth.Project(out.depth_from_board * p), kind});
  };
  for (int j = 1; j < board.squares_y; ++j)
    for (int i = 1; i < board.squares_x; ++i) add(i * s, j * s, SamplePoint::kInteriorCorner);
  if (options.square_centres) {
    for (int j = 0; j < board.squares_y; ++j)
      for (int i = 0; i < board.squares_x; ++i) add((i + 0.5) * s, (j + 0.5) * s, SamplePoint::kSquareCentre);
  }
  out.board = board;
  return out;
}

double BoardAlbedo(const BoardGeometry& board, const Eigen::Vector2d& in_board) {
  const int i = static_cast<int>(std::floor(in_board.x() / board.square_size_m));
  const int j = static_cast<int>(std::floor(in_board.y() / board.square_size_m));
  if (i < 0 || j < 0 || i >= board.squares_x || j >= board.squares_y) return 0.5;
  return (i + j) % 2 == 0 ? 0.0 : 1.0;
}

}  // namespace speckle
