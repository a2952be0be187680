#include "stages/records.h"

#include <fmt/format.h>

#include "schemas/brown_conrady.h"

namespace speckle {

std::string JointAccount::Term::Scatter() const {
  return observations > 0 ? fmt::format("{:.3f} {} rms", rms, unit) : "none";
}

std::vector<cv::Point3f> BoardGeometry::InteriorCornerPoints() const {
  std::vector<cv::Point3f> points;
  for (int j = 1; j < squares_y; ++j)
    for (int i = 1; i < squares_x; ++i)
      points.emplace_back(static_cast<float>(i * square_size_m), static_cast<float>(j * square_size_m), 0.f);
  return points;
}

Eigen::Vector2d CameraIntrinsics::Undistort(const Eigen::Vector2d& pixel) const {
  return lens::Undistort({(pixel.x() - camera_matrix(0, 2)) / camera_matrix(0, 0),
                          (pixel.y() - camera_matrix(1, 2)) / camera_matrix(1, 1)},
                         distortion);
}

Eigen::Vector2d CameraIntrinsics::Project(const Eigen::Vector3d& p) const {
  const Eigen::Vector2d d = lens::Distort({p.x() / p.z(), p.y() / p.z()}, distortion);
  return {camera_matrix(0, 0) * d.x() + camera_matrix(0, 2), camera_matrix(1, 1) * d.y() + camera_matrix(1, 2)};
}

}  // namespace speckle
