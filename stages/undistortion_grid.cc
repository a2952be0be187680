#include "stages/undistortion_grid.h"

#include <algorithm>
#include <cmath>

namespace speckle {

namespace {

// One cell's mean raw in one snapshot, its standard error, and the correction.
struct CellPoint {
  double raw, correction, std_error;
};

// Per cell (row-major), the points of every snapshot that covers it.
std::vector<std::vector<CellPoint>> CellPoints(const UndistortionGridOptions& options, const UndistortionGrid& g,
                                               const std::vector<PlanarSnapshot>& snapshots) {
  std::vector<std::vector<CellPoint>> cells(static_cast<std::size_t>(g.nx * g.ny));
  for (const auto& s : snapshots) {
    std::vector<double> sum(cells.size()), sum_sq(cells.size()), sum_truth(cells.size());
    std::vector<int> count(cells.size());
    for (const auto& p : s.inliers) {
      const int i = std::clamp(static_cast<int>((p.x - g.x_min) / (g.x_max - g.x_min) * g.nx), 0, g.nx - 1);
      const int j = std::clamp(static_cast<int>((p.y - g.y_min) / (g.y_max - g.y_min) * g.ny), 0, g.ny - 1);
      const std::size_t c = static_cast<std::size_t>(j * g.nx + i);
      sum[c] += p.raw, sum_sq[c] += p.raw * p.raw, sum_truth[c] += s.TrueRaw(g.method, p.x, p.y), ++count[c];
    }
    for (std::size_t c = 0; c < cells.size(); ++c) {
      if (count[c] < options.min_pixels_per_cell) continue;
      const double mean = sum[c] / count[c];
      const double var = std::max(0.0, sum_sq[c] / count[c] - mean * mean);
      cells[c].push_back(
          {mean, sum_truth[c] / count[c] - mean, std::sqrt(var / count[c]) + 1.0 / std::sqrt(12.0 * count[c])});
    }
  }
  for (auto& points : cells)
    std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) { return a.raw < b.raw; });
  return cells;
}

// The cell's correction at raw value r; `inside` when r lies between two of
// its snapshots (outside, the nearest snapshot's value is held).
CellPoint CorrectionAt(const UndistortionGridOptions& options, const std::vector<CellPoint>& points, double r,
                       bool& inside) {
  inside = false;
  const auto above =
      std::lower_bound(points.begin(), points.end(), r, [](const CellPoint& p, double value) { return p.raw < value; });
  if (above == points.begin()) {
    return points.front();
  } else if (above == points.end()) {
    return points.back();
  } else {
    const CellPoint& a = *(above - 1);
    const CellPoint& b = *above;
    // Billowing's correction falls as 1/r (thesis Eq. 4.2: sqrt(r^2 + B) - r
    // ~ B / 2r), so it is interpolated linearly in 1/r: linear in r it
    // sagged up to 1.5 raw between near snapshots, where r changes fast.
    const double t = options.interpolate_in_inverse_raw && a.raw > 0 && b.raw > 0
                         ? (1 / r - 1 / a.raw) / (1 / b.raw - 1 / a.raw)
                         : (r - a.raw) / (b.raw - a.raw);
    inside = true;
    return {r, a.correction + t * (b.correction - a.correction), a.std_error + t * (b.std_error - a.std_error)};
  }
}

}  // namespace

StageResult<UndistortionGrid> RunUndistortionGridBuild(const UndistortionGridOptions& options,
                                                       const std::vector<PlanarSnapshot>& snapshots) {
  if (snapshots.size() < 2) {
    return Rejection{"undistortion_grid",
                     "needs at least 2 clean planar snapshots, found " + std::to_string(snapshots.size())};
  }
  UndistortionGrid g;
  g.nx = options.cells_x;
  g.ny = options.cells_y;
  g.method = options.method;
  for (const auto& s : snapshots) g.max_tilt_deg = std::max(g.max_tilt_deg, s.tilt_deg);
  if (g.max_tilt_deg > options.max_square_tilt_deg) g.method = TrueRawMethod::kOwnPlane;
  g.x_min = g.y_min = 1e9;
  g.x_max = g.y_max = -1e9;
  double raw_lo = 1e9, raw_hi = -1e9;
  for (const auto& s : snapshots) {
    for (const auto& p : s.inliers) {
      g.x_min = std::min(g.x_min, p.x), g.x_max = std::max(g.x_max, p.x);
      g.y_min = std::min(g.y_min, p.y), g.y_max = std::max(g.y_max, p.y);
      raw_lo = std::min(raw_lo, p.raw), raw_hi = std::max(raw_hi, p.raw);
    }
  }
  for (int k = 0; k < options.raw_nodes; ++k)
    g.raw_nodes.push_back(raw_lo + (raw_hi - raw_lo) * k / (options.raw_nodes - 1));

  const std::vector<std::vector<CellPoint>> cells = CellPoints(options, g, snapshots);
  const std::size_t nodes = g.raw_nodes.size() * cells.size();
  g.correction.assign(nodes, 0.f);
  g.std_error.assign(nodes, 0.f);
  g.supported.assign(nodes, 0);
  for (int j = 0; j < g.ny; ++j) {
    for (int i = 0; i < g.nx; ++i) {
      const auto& points = cells[static_cast<std::size_t>(j * g.nx + i)];
      if (points.empty()) continue;
      for (int k = 0; k < static_cast<int>(g.raw_nodes.size()); ++k) {
        const double r = g.raw_nodes[static_cast<std::size_t>(k)];
        bool inside = false;
        const CellPoint value = CorrectionAt(options, points, r, inside);
        g.correction[g.Index(k, j, i)] = static_cast<float>(value.correction);
        g.std_error[g.Index(k, j, i)] = static_cast<float>(value.std_error);
        g.supported[g.Index(k, j, i)] = inside;
      }
    }
  }
  return g;
}

}  // namespace speckle
