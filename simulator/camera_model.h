#pragma once
// Pinhole camera with Brown-Conrady distortion (k1, k2, p1, p2, k3), the
// model OpenCV calibrates. Points are in the camera's frame, metres, z ahead.
#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>

namespace speckle::sim {

struct CameraModel {
  cv::Size size{640, 480};
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::array<double, 5> distortion{};  // k1, k2, p1, p2, k3

  // Pixel of a point in front of the camera (z > 0).
  Eigen::Vector2d Project(const Eigen::Vector3d& point) const;
  // Pixel of normalized undistorted coordinates (x/z, y/z), and its inverse
  // (NaN where the distortion model has no inverse: far corners of strong lenses).
  Eigen::Vector2d Distort(const Eigen::Vector2d& xy) const;
  Eigen::Vector2d Undistort(const Eigen::Vector2d& pixel) const;
  // Normalized undistorted coordinates (x/z, y/z) of every pixel centre, and
  // of every supersampled position when `samples_per_axis` > 1. Row-major,
  // (height*s) x (width*s).
  std::vector<Eigen::Vector2d> PixelRays(int samples_per_axis = 1) const;
};

}  // namespace speckle::sim
