#include "simulator/camera_model.h"

#include <tbb/parallel_for.h>

#include <Eigen/Dense>
#include <cmath>

namespace speckle::sim {

Eigen::Vector2d CameraModel::Project(const Eigen::Vector3d& p) const {
  return Distort({p.x() / p.z(), p.y() / p.z()});
}

Eigen::Vector2d CameraModel::Distort(const Eigen::Vector2d& xy) const {
  const double x = xy.x(), y = xy.y();
  const auto [k1, k2, p1, p2, k3] = distortion;
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const double yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  return {fx * xd + cx, fy * yd + cy};
}

Eigen::Vector2d CameraModel::Undistort(const Eigen::Vector2d& pixel) const {
  // Newton's method on Distort(xy) = pixel, from the pinhole guess; the
  // Jacobian by central differences is plenty for a smooth 2-D map.
  Eigen::Vector2d xy((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
  constexpr double h = 1e-7;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const Eigen::Vector2d error = Distort(xy) - pixel;
    if (error.squaredNorm() < 1e-20) break;
    Eigen::Matrix2d jacobian;
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector2d step = Eigen::Vector2d::Unit(k) * h;
      jacobian.col(k) = (Distort(xy + step) - Distort(xy - step)) / (2 * h);
    }
    xy -= jacobian.partialPivLu().solve(error);
  }
  // Beyond the radius where the radial polynomial stops growing, a pixel has
  // no true ray (Newton lands on a spurious root): the lens model does not
  // hold there, so report none.
  const auto [k1, k2, p1, p2, k3] = distortion;
  const double r2 = xy.squaredNorm();
  const double slope = 1 + r2 * (3 * k1 + r2 * (5 * k2 + r2 * 7 * k3));
  if ((Distort(xy) - pixel).norm() > 1e-6 || slope <= 0) return Eigen::Vector2d::Constant(std::nan(""));
  return xy;
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
