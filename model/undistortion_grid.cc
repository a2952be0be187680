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

namespace {

// Where (raw, x, y) falls among the nodes: the two raw nodes and the four
// cells around it, with their interpolation weights (cell centres at
// integers; clamped at the edges).
struct Corners {
  int k1, i0, i1, j0, j1;
  double fk, ti, tj;
};

Corners CornersOf(const UndistortionGrid& g, double raw, double x, double y) {
  const double fi = std::clamp((x - g.x_min) / (g.x_max - g.x_min) * g.nx - 0.5, 0.0, g.nx - 1.0);
  const double fj = std::clamp((y - g.y_min) / (g.y_max - g.y_min) * g.ny - 0.5, 0.0, g.ny - 1.0);
  const auto& nodes = g.raw_nodes;
  const auto upper = std::upper_bound(nodes.begin(), nodes.end(), raw);
  const int k1 = std::clamp(static_cast<int>(upper - nodes.begin()), 1, static_cast<int>(nodes.size()) - 1);
  const double fk = std::clamp((raw - nodes[k1 - 1]) / (nodes[k1] - nodes[k1 - 1]), 0.0, 1.0);
  const int i0 = static_cast<int>(fi), j0 = static_cast<int>(fj);
  return {k1, i0, std::min(i0 + 1, g.nx - 1), j0, std::min(j0 + 1, g.ny - 1), fk, fi - i0, fj - j0};
}

// An unsound grid (see Problem()) is refused where it is read; this keeps
// the lookups from reading outside the arrays even so.
bool Readable(const UndistortionGrid& g, const std::vector<float>& values, double raw, double x, double y) {
  return g.nx > 0 && g.ny > 0 && g.raw_nodes.size() >= 2 && values.size() == g.raw_nodes.size() * g.nx * g.ny &&
         std::isfinite(raw) && std::isfinite(x) && std::isfinite(y);
}

}  // namespace

double UndistortionGrid::Apply(double raw, double x, double y) const {
  if (!Readable(*this, correction, raw, x, y)) return raw;
  const Corners c = CornersOf(*this, raw, x, y);
  double value = 0;
  for (int dk = 0; dk < 2; ++dk) {
    const int k = c.k1 - 1 + dk;
    const double wk = dk ? c.fk : 1 - c.fk;
    value +=
        wk * ((1 - c.tj) * ((1 - c.ti) * correction[Index(k, c.j0, c.i0)] + c.ti * correction[Index(k, c.j0, c.i1)]) +
              c.tj * ((1 - c.ti) * correction[Index(k, c.j1, c.i0)] + c.ti * correction[Index(k, c.j1, c.i1)]));
  }
  return raw + value;
}

double UndistortionGrid::StdErrorAt(double raw, double x, double y) const {
  if (!Readable(*this, std_error, raw, x, y)) return 0;
  const Corners c = CornersOf(*this, raw, x, y);
  const auto cell = [&](int j, int i) {  // along raw: correlated, so the errors add
    return (1 - c.fk) * std_error[Index(c.k1 - 1, j, i)] + c.fk * std_error[Index(c.k1, j, i)];
  };
  const auto squared = [](double v) { return v * v; };
  double variance = 0;
  for (const auto& [j, wj] : {std::pair{c.j0, 1 - c.tj}, std::pair{c.j1, c.tj}})
    for (const auto& [i, wi] : {std::pair{c.i0, 1 - c.ti}, std::pair{c.i1, c.ti}})
      variance += squared(wj * wi * cell(j, i));
  return std::sqrt(variance);
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
