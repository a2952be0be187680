#include "model/undistortion_grid.h"

#include <algorithm>
#include <cmath>

namespace speckle {

const char* ToString(TrueRawMethod method) {
  switch (method) {
    case TrueRawMethod::kImageMinimum:
      return "image_minimum";
    case TrueRawMethod::kHyperboloid:
      return "hyperboloid";
    case TrueRawMethod::kCentreMinimum:
      return "centre_minimum";
    case TrueRawMethod::kOwnPlane:
      return "own_plane";
  }
  return "?";
}

double UndistortionGrid::Apply(double raw, double x, double y) const {
  // An unsound grid (see Problem()) is refused where it is read; this keeps
  // Apply from reading outside the arrays even so.
  if (nx <= 0 || ny <= 0 || raw_nodes.size() < 2 || correction.size() != raw_nodes.size() * nx * ny) return raw;
  if (!std::isfinite(raw) || !std::isfinite(x) || !std::isfinite(y)) return raw;
  // Continuous cell coordinates (cell centres at integers).
  const double fi = std::clamp((x - x_min) / (x_max - x_min) * nx - 0.5, 0.0, nx - 1.0);
  const double fj = std::clamp((y - y_min) / (y_max - y_min) * ny - 0.5, 0.0, ny - 1.0);
  const auto upper = std::upper_bound(raw_nodes.begin(), raw_nodes.end(), raw);
  const int k1 = std::clamp(static_cast<int>(upper - raw_nodes.begin()), 1, static_cast<int>(raw_nodes.size()) - 1);
  const double fk = std::clamp((raw - raw_nodes[k1 - 1]) / (raw_nodes[k1] - raw_nodes[k1 - 1]), 0.0, 1.0);
  const int i0 = static_cast<int>(fi), j0 = static_cast<int>(fj);
  const int i1 = std::min(i0 + 1, nx - 1), j1 = std::min(j0 + 1, ny - 1);
  const double ti = fi - i0, tj = fj - j0;
  double value = 0;
  for (int dk = 0; dk < 2; ++dk) {
    const int k = k1 - 1 + dk;
    const double wk = dk ? fk : 1 - fk;
    value += wk * ((1 - tj) * ((1 - ti) * correction[Index(k, j0, i0)] + ti * correction[Index(k, j0, i1)]) +
                   tj * ((1 - ti) * correction[Index(k, j1, i0)] + ti * correction[Index(k, j1, i1)]));
  }
  return raw + value;
}

double UndistortionGrid::SupportedShare() const {
  if (supported.empty()) return 0;
  return static_cast<double>(std::count(supported.begin(), supported.end(), 1)) / supported.size();
}

}  // namespace speckle

namespace speckle {

std::string UndistortionGrid::Problem() const {
  for (double v : {x_min, x_max, y_min, y_max})
    if (!std::isfinite(v) || std::abs(v) > 100)
      return "extent_x_min_x_max_y_min_y_max: expected finite normalized coordinates within +-100";
  if (!(x_min < x_max) || !(y_min < y_max))
    return "extent_x_min_x_max_y_min_y_max: expected x_min < x_max and y_min < y_max";
  if (nx < 1 || ny < 1 || nx > kMaxGridCells || ny > kMaxGridCells)
    return "correction: expected 1 to " + std::to_string(kMaxGridCells) + " cells along x and y, found " +
           std::to_string(nx) + " x " + std::to_string(ny);
  if (raw_nodes.size() < 2 || raw_nodes.size() > static_cast<std::size_t>(kMaxGridNodes))
    return "raw_nodes: expected 2 to " + std::to_string(kMaxGridNodes) + " nodes, found " +
           std::to_string(raw_nodes.size());
  for (std::size_t k = 0; k < raw_nodes.size(); ++k) {
    if (!std::isfinite(raw_nodes[k]) || raw_nodes[k] < 0 || raw_nodes[k] > 1e5)
      return "raw_nodes[" + std::to_string(k) + "]: expected a raw value in [0, 1e5]";
    if (k > 0 && !(raw_nodes[k] - raw_nodes[k - 1] >= kMinNodeSpacingRaw))
      return "raw_nodes[" + std::to_string(k) + "]: expected nodes increasing by at least " +
             std::to_string(kMinNodeSpacingRaw) + " raw, found " + std::to_string(raw_nodes[k - 1]) + " then " +
             std::to_string(raw_nodes[k]);
  }
  const std::size_t n = raw_nodes.size() * static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  if (correction.size() != n || std_error.size() != n || supported.size() != n)
    return "correction, std_error, supported: expected " + std::to_string(n) + " values each (nodes x ny x nx)";
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(correction[i]) || std::abs(correction[i]) > 1e4)
      return "correction: value " + std::to_string(i) + " is not a finite raw offset within +-1e4";
  return {};
}

}  // namespace speckle
