#include "simulator/camera_model.h"

#include <tbb/parallel_for.h>

#include "schemas/brown_conrady.h"

namespace speckle::sim {

Eigen::Vector2d CameraModel::Project(const Eigen::Vector3d& p) const { return Distort({p.x() / p.z(), p.y() / p.z()}); }

Eigen::Vector2d CameraModel::Distort(const Eigen::Vector2d& xy) const {
  const Eigen::Vector2d d = lens::Distort(xy, distortion);
  return {fx * d.x() + cx, fy * d.y() + cy};
}

Eigen::Vector2d CameraModel::Undistort(const Eigen::Vector2d& pixel) const {
  return lens::Undistort({(pixel.x() - cx) / fx, (pixel.y() - cy) / fy}, distortion);
}

std::vector<Eigen::Vector2d> CameraModel::PixelRays(int s) const {
  const int w = size.width * s, h = size.height * s;
  std::vector<Eigen::Vector2d> rays(static_cast<std::size_t>(w) * h);
  tbb::parallel_for(0, h, [&](int v) {
    for (int u = 0; u < w; ++u) {
      rays[static_cast<std::size_t>(v) * w + u] = Undistort({(u + 0.5) / s - 0.5, (v + 0.5) / s - 0.5});
    }
  });
  return rays;
}

}  // namespace speckle::sim
