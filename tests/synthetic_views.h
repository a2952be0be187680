#pragma once
// Known truths for the stage tests: cameras, board poses spread as a user
// records them, and chessboard images drawn by OpenCV through a known camera
// and pose. No simulator and no session files: a stage test links only
// speckle_stages, and its truth is written here in a few lines.
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "stages/records.h"

namespace speckle::synthetic {

inline CameraIntrinsics Camera(double fx, double fy, double cx, double cy, std::array<double, 5> distortion = {},
                               cv::Size size = {640, 480}) {
  CameraIntrinsics c;
  c.image_size = size;
  c.camera_matrix = cv::Matx33d(fx, 0, cx, 0, fy, cy, 0, 0, 1);
  c.distortion = distortion;
  return c;
}

// What the pipeline starts the colour-to-depth rig from: the nominal Kinect
// rig, the depth camera 2.5 cm along x.
inline Eigen::Isometry3d NominalDepthFromColour() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(-0.025, 0, 0);
  return t;
}

// camera_from_board for a board whose centre sits at `centre_m` in the
// camera, tilted about its own x and y axes and rolled about its normal
// (degrees). With no tilt or roll the board's x runs along the image's
// columns and its normal points away from the camera (OpenCV's convention).
inline Eigen::Isometry3d BoardPose(const BoardGeometry& board, const Eigen::Vector3d& centre_m, double tilt_x_deg,
                                   double tilt_y_deg, double roll_deg) {
  const double to_rad = M_PI / 180;
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(tilt_x_deg * to_rad, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(tilt_y_deg * to_rad, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(roll_deg * to_rad, Eigen::Vector3d::UnitZ()))
                                .toRotationMatrix();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = r;
  pose.translation() = centre_m - r * Eigen::Vector3d(board.Width() / 2, board.Height() / 2, 0);
  return pose;
}

// Poses as a calibration engineer records them: `near_m` to `far_m` away, up
// to 35 degrees of tilt about each board axis and 20 of roll, the board's
// centre within 10 degrees of the optical axis.
inline std::vector<Eigen::Isometry3d> SpreadPoses(const BoardGeometry& board, int n, std::mt19937& rng,
                                                  double near_m = 0.6, double far_m = 1.8) {
  std::uniform_real_distribution<double> depth(near_m, far_m), tilt(-35, 35), roll(-20, 20), across(-0.18, 0.18);
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < n; ++i) {
    const double z = depth(rng);
    poses.push_back(BoardPose(board, {across(rng) * z, across(rng) * z, z}, tilt(rng), tilt(rng), roll(rng)));
  }
  return poses;
}

inline cv::Point2f ProjectPoint(const CameraIntrinsics& camera, const Eigen::Vector3d& p) {
  const Eigen::Vector2d px = camera.Project(p);
  return {static_cast<float>(px.x()), static_cast<float>(px.y())};
}

// The board's interior corners as `camera` sees them at `camera_from_board`,
// in the stages' row-major order from square (0, 0).
inline std::vector<cv::Point2f> ProjectCorners(const CameraIntrinsics& camera, const BoardGeometry& board,
                                               const Eigen::Isometry3d& camera_from_board) {
  std::vector<cv::Point2f> out;
  for (const auto& p : board.InteriorCornerPoints())
    out.push_back(ProjectPoint(camera, camera_from_board * Eigen::Vector3d(p.x, p.y, p.z)));
  return out;
}

// Adds zero-mean Gaussian noise of `sigma_px` to each coordinate.
inline std::vector<cv::Point2f> Jitter(std::vector<cv::Point2f> points, double sigma_px, std::mt19937& rng) {
  std::normal_distribution<double> noise(0, sigma_px);
  for (auto& p : points) p += cv::Point2f(static_cast<float>(noise(rng)), static_cast<float>(noise(rng)));
  return points;
}

// A grey image of the chessboard, square (0, 0) dark, with a white border one
// square wide, on a mid-grey wall, drawn through a pinhole `camera` (its
// distortion is ignored: the board maps to the image by a homography). Drawn
// at 4x resolution and area-averaged down, so edges are anti-aliased as a
// real sensor's pixels integrate light; `blur_px` is a lens's Gaussian blur
// (sigma, image pixels) and `noise_grey` the sensor noise.
inline cv::Mat RenderChessboard(const CameraIntrinsics& camera, const BoardGeometry& board,
                                const Eigen::Isometry3d& camera_from_board, double noise_grey, std::mt19937& rng,
                                double blur_px = 0) {
  constexpr int kPixelsPerSquare = 40, kFine = 4;
  const double s = board.square_size_m;
  cv::Mat texture((board.squares_y + 2) * kPixelsPerSquare, (board.squares_x + 2) * kPixelsPerSquare, CV_8U, 235);
  for (int j = 0; j < board.squares_y; ++j)
    for (int i = 0; i < board.squares_x; ++i)
      if ((i + j) % 2 == 0)
        texture(cv::Rect((i + 1) * kPixelsPerSquare, (j + 1) * kPixelsPerSquare, kPixelsPerSquare, kPixelsPerSquare))
            .setTo(25);
  // Pixel centres sit at integer coordinates (OpenCV's convention): texture
  // pixel t shows board x = (t + 0.5 - kPixelsPerSquare) s / kPixelsPerSquare,
  // and fine pixel kFine u + (kFine - 1) / 2 is the centre of image pixel u.
  const double per_px = s / kPixelsPerSquare;
  const Eigen::Matrix3d board_from_texture{
      {per_px, 0, (0.5 - kPixelsPerSquare) * per_px}, {0, per_px, (0.5 - kPixelsPerSquare) * per_px}, {0, 0, 1}};
  Eigen::Matrix3d plane;  // board (x, y, 1) -> camera, for z = 0
  plane << camera_from_board.linear().col(0), camera_from_board.linear().col(1), camera_from_board.translation();
  const cv::Matx33d& m = camera.camera_matrix;
  const Eigen::Matrix3d k{{m(0, 0), 0, m(0, 2)}, {0, m(1, 1), m(1, 2)}, {0, 0, 1}};
  const Eigen::Matrix3d fine{{kFine, 0, (kFine - 1) / 2.0}, {0, kFine, (kFine - 1) / 2.0}, {0, 0, 1}};
  const Eigen::Matrix3d h = fine * k * plane * board_from_texture;
  cv::Matx33d h_cv;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) h_cv(r, c) = h(r, c);
  cv::Mat drawn, image;
  cv::warpPerspective(texture, drawn, h_cv, camera.image_size * kFine, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 128);
  cv::resize(drawn, image, camera.image_size, 0, 0, cv::INTER_AREA);
  if (blur_px > 0) cv::GaussianBlur(image, image, cv::Size(0, 0), blur_px);
  cv::Mat noisy(image.size(), CV_32F);
  image.convertTo(noisy, CV_32F);
  std::normal_distribution<float> noise(0, static_cast<float>(noise_grey));
  for (auto it = noisy.begin<float>(); it != noisy.end<float>(); ++it) *it += noise(rng);
  noisy.convertTo(image, CV_8U);  // saturates at 0 and 255
  return image;
}

}  // namespace speckle::synthetic
