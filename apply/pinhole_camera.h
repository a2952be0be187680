#pragma once
// A camera of an applied calibration: pinhole intrinsics and the
// Brown-Conrady lens OpenCV calibrates (schemas/brown_conrady.h).
#include <Eigen/Core>

#include "schemas/brown_conrady.h"

namespace speckle::apply {

struct PinholeCamera {
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  lens::Coefficients distortion{};  // k1, k2, p1, p2, k3

  // A pixel's ray as undistorted (x/z, y/z); NaN beyond the lens model's invertible radius.
  Eigen::Vector2d Ray(double u, double v) const { return lens::Undistort({(u - cx) / fx, (v - cy) / fy}, distortion); }
  // A point in this camera's coordinates to its (distorted) pixel.
  Eigen::Vector2d Project(const Eigen::Vector3d& p) const {
    const Eigen::Vector2d d = lens::Distort(Eigen::Vector2d(p.x() / p.z(), p.y() / p.z()), distortion);
    return {fx * d.x() + cx, fy * d.y() + cy};
  }
};

}  // namespace speckle::apply
