#include "apply/registered_depth.h"

#include <cmath>
#include <limits>

namespace speckle::apply {

std::vector<float> RegisteredDepth(const OrganizedCloud& cloud, const DepthCalibration& calibration) {
  const PinholeCamera& colour = calibration.colour;
  std::vector<float> out(static_cast<std::size_t>(colour.width) * static_cast<std::size_t>(colour.height),
                         std::numeric_limits<float>::quiet_NaN());
  const Eigen::Isometry3d colour_from_depth = calibration.depth_from_colour.inverse();
  for (std::size_t p = 0; p + 2 < cloud.xyz.size(); p += 3) {
    if (!std::isfinite(cloud.xyz[p + 2])) continue;
    const Eigen::Vector3d q = colour_from_depth * Eigen::Vector3d(cloud.xyz[p], cloud.xyz[p + 1], cloud.xyz[p + 2]);
    if (!(q.z() > 0)) continue;
    const Eigen::Vector2d pixel = colour.Project(q);
    const long u = std::lround(pixel.x()), v = std::lround(pixel.y());
    if (!std::isfinite(pixel.x()) || !std::isfinite(pixel.y()) || u < 0 || v < 0 || u >= colour.width ||
        v >= colour.height)
      continue;
    float& z = out[static_cast<std::size_t>(v) * static_cast<std::size_t>(colour.width) + static_cast<std::size_t>(u)];
    if (!(z <= q.z())) z = static_cast<float>(q.z());  // NaN or farther: this point is seen
  }
  return out;
}

}  // namespace speckle::apply
