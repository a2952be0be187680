#include "apply/point_measure.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "model/depth_model.h"
#include "schemas/errors.h"

namespace speckle::apply {
namespace {

double Median(std::vector<double>& values) {
  const auto middle = values.begin() + static_cast<long>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  if (values.size() % 2) return *middle;
  return 0.5 * (*middle + *std::max_element(values.begin(), middle));
}

void RequireInside(const OrganizedCloud& cloud, int u, int v) {
  if (u < 0 || v < 0 || u >= cloud.width || v >= cloud.height)
    throw InputError(fmt::format("pixel ({}, {}) is outside the {} x {} depth image", u, v, cloud.width, cloud.height));
}

}  // namespace

std::optional<PixelPoint> PointAt(const OrganizedCloud& cloud, int u, int v, int window) {
  RequireInside(cloud, u, v);
  std::vector<double> axis[3];
  for (int y = std::max(0, v - window); y <= std::min(cloud.height - 1, v + window); ++y) {
    for (int x = std::max(0, u - window); x <= std::min(cloud.width - 1, u + window); ++x) {
      const float* p = &cloud.xyz[3 * (static_cast<std::size_t>(y) * cloud.width + x)];
      if (!std::isfinite(p[2])) continue;
      for (int a = 0; a < 3; ++a) axis[a].push_back(p[a]);
    }
  }
  if (axis[2].empty()) return std::nullopt;
  PixelPoint point{u, v, {}, static_cast<int>(axis[2].size())};
  for (int a = 0; a < 3; ++a) point.xyz[a] = Median(axis[a]);
  return point;
}

Measurement Measure(const OrganizedCloud& cloud, int from_u, int from_v, int to_u, int to_v, int window) {
  // A pixel outside the image is named before a missing reading at the other: the first is always a typo.
  RequireInside(cloud, from_u, from_v), RequireInside(cloud, to_u, to_v);
  const auto pick = [&](int u, int v) {
    const std::optional<PixelPoint> p = PointAt(cloud, u, v, window);
    if (!p) {
      throw InputError(fmt::format("pixel ({}, {}): no depth reading{}; pick another pixel or widen --window", u, v,
                                   window ? fmt::format(" within {} pixels", window) : ""));
    }
    return *p;
  };
  Measurement m{pick(from_u, from_v), pick(to_u, to_v), {}, 0};
  m.displacement = m.to.xyz - m.from.xyz;
  m.distance_m = m.displacement.norm();
  return m;
}

double DepthSigmaTable::At(double depth) const {
  if (depth_m.empty()) return 0;
  if (depth <= depth_m.front()) return sigma_m.front() / depth_m.front() * depth;
  if (depth >= depth_m.back()) return sigma_m.back() / depth_m.back() * depth;
  const auto above = std::upper_bound(depth_m.begin(), depth_m.end(), depth);
  const std::size_t i = static_cast<std::size_t>(above - depth_m.begin());
  const double t = (depth - depth_m[i - 1]) / (depth_m[i] - depth_m[i - 1]);
  return sigma_m[i - 1] + t * (sigma_m[i] - sigma_m[i - 1]);
}

bool DepthSigmaTable::Covers(double depth) const {
  return !depth_m.empty() && depth >= depth_m.front() && depth <= depth_m.back();
}

double DistanceSigma(const Measurement& m, const DepthSigmaTable& table) {
  if (m.distance_m <= 0) return 0;
  const Eigen::Vector3d along = m.displacement / m.distance_m;
  // A point moved by dz along its ray moves by p * dz / z.
  const auto shift = [&](const PixelPoint& p) { return p.xyz.dot(along) * table.At(p.xyz.z()) / p.xyz.z(); };
  const double from = shift(m.from), to = shift(m.to);
  return std::max(std::abs(to - from), std::hypot(from, to));
}

}  // namespace speckle::apply
