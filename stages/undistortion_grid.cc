#include "stages/undistortion_grid.h"

#include "schemas/option_check.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

#include <tbb/parallel_for.h>

namespace speckle {

namespace {

// One cell's raw value in one snapshot, its standard error, and the correction.
struct CellPoint {
  double raw, correction, std_error;
};

// One snapshot's pixels in one cell, for planes over (1, dx, dy): dx, dy the
// pixel's offset from the cell's centre in cell widths.
struct CellSums {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d raw = Eigen::Vector3d::Zero(), correction = Eigen::Vector3d::Zero();
  double raw_squares = 0;
  int count = 0;
};

// The cell's raw value and correction at its centre, each a plane fitted
// over its pixels (a small ridge holds the slopes where the pixels lie on a
// line). Their means would stand for the pixels' centroid, and the grid is
// interpolated between cell centres: towards the image's edge, where
// billowing changes by up to 0.4 raw a pixel, walls sampled one pixel in 7
// were given back 0.5-0.7 raw wrong (0.1 at the centre).
CellPoint AtCentre(CellSums sums) {
  const double n = sums.count;
  sums.normal.diagonal().tail<2>().array() += 1e-3 * n;
  const Eigen::LDLT<Eigen::Matrix3d> solver(sums.normal);
  const Eigen::Vector3d raw = solver.solve(sums.raw), correction = solver.solve(sums.correction);
  const double scatter = std::max(0.0, sums.raw_squares - raw.dot(sums.raw)) / std::max(1.0, n - 3);
  return {raw(0), correction(0), std::sqrt(scatter / n) + 1.0 / std::sqrt(12.0 * n)};
}

// One snapshot's point in each cell (row-major), where it has enough pixels.
using SnapshotPoints = std::vector<std::optional<CellPoint>>;

SnapshotPoints PointsOf(const UndistortionGridOptions& options, const UndistortionGrid& g, const PlanarSnapshot& s) {
  std::vector<CellSums> sums(static_cast<std::size_t>(g.nx * g.ny));
  for (const auto& p : s.inliers) {
    const double fx = (p.x - g.x_min) / (g.x_max - g.x_min) * g.nx, fy = (p.y - g.y_min) / (g.y_max - g.y_min) * g.ny;
    const int i = std::clamp(static_cast<int>(fx), 0, g.nx - 1), j = std::clamp(static_cast<int>(fy), 0, g.ny - 1);
    CellSums& c = sums[static_cast<std::size_t>(j * g.nx + i)];
    const Eigen::Vector3d row(1, fx - i - 0.5, fy - j - 0.5);
    c.normal += row * row.transpose();
    c.raw += row * p.raw;
    c.correction += row * (s.TrueRaw(g.method, p.x, p.y) - p.raw);
    c.raw_squares += p.raw * p.raw;
    ++c.count;
  }
  SnapshotPoints points(sums.size());
  for (std::size_t c = 0; c < sums.size(); ++c)
    if (sums[c].count >= options.min_pixels_per_cell) points[c] = AtCentre(sums[c]);
  return points;
}

// Per cell, the points of every snapshot that covers it (but `left_out`),
// ordered by raw value.
std::vector<std::vector<CellPoint>> CellPoints(const std::vector<SnapshotPoints>& snapshots,
                                               std::size_t left_out = SIZE_MAX) {
  std::vector<std::vector<CellPoint>> cells(snapshots.empty() ? 0 : snapshots.front().size());
  for (std::size_t k = 0; k < snapshots.size(); ++k) {
    if (k == left_out) continue;
    for (std::size_t c = 0; c < cells.size(); ++c)
      if (snapshots[k][c]) cells[c].push_back(*snapshots[k][c]);
  }
  for (auto& points : cells)
    std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) { return a.raw < b.raw; });
  return cells;
}

// Where r lies from a (0) to b (1): linear in 1/r, as billowing's correction
// falls (thesis Eq. 4.2: sqrt(r^2 + B) - r ~ B / 2r), else linear in r (the
// thesis). Linear in r it sagged up to 1.5 raw between near snapshots, where
// r changes fast.
double Position(const UndistortionGridOptions& options, const CellPoint& a, const CellPoint& b, double r) {
  if (options.interpolate_in_inverse_raw && a.raw > 0 && b.raw > 0 && r > 0)
    return (1 / r - 1 / a.raw) / (1 / b.raw - 1 / a.raw);
  return (r - a.raw) / (b.raw - a.raw);
}

// The cell's correction at raw value r; `inside` when r lies between two of
// its snapshots.
CellPoint CorrectionAt(const UndistortionGridOptions& options, const std::vector<CellPoint>& points, double r,
                       bool& inside) {
  inside = false;
  const auto above =
      std::lower_bound(points.begin(), points.end(), r, [](const CellPoint& p, double value) { return p.raw < value; });
  if (above != points.begin() && above != points.end()) {
    const CellPoint& a = *(above - 1);
    const CellPoint& b = *above;
    const double t = Position(options, a, b, r);
    inside = true;
    return {r, a.correction + t * (b.correction - a.correction), a.std_error + t * (b.std_error - a.std_error)};
  }
  // Nearer or farther than every wall that covers the cell (clutter hid the
  // nearest wall there, say): the same line carried out from the nearest
  // snapshot, through the first one at least as far from it as r is, so no
  // slope is stretched beyond the span it was measured over. Held at the
  // nearest snapshot's value instead, a board 5 cm nearer than a cell's
  // nearest wall was corrected up to 4.5 raw short.
  const bool nearer = above == points.begin();
  const CellPoint& a = nearer ? points.front() : points.back();
  const std::size_t last = points.size() - 1;
  const CellPoint* b = nullptr;
  for (std::size_t i = 1; i <= last; ++i) {
    const CellPoint& candidate = points[nearer ? i : last - i];
    if (candidate.raw == a.raw) continue;
    b = &candidate;
    if (std::abs(Position(options, a, *b, r)) <= 1) break;
  }
  if (!b) return a;
  const double t = Position(options, a, *b, r);
  return {r, a.correction + t * (b->correction - a.correction),
          a.std_error + std::abs(t) * (a.std_error + b->std_error)};
}

// Cells no wall reached (outside the adapter's usable circle, or where every
// wall's mask left a corner out) are filled ring by ring from the filled
// cells around them, each carried on linearly (2 v(c + d) - v(c + 2d)), or
// held where only one lies that way; they stay unsupported. Left at zero,
// the grid's interpolation pulled pixels just inside the circle's edge
// towards no correction: 6 raw off.
void FillEmptyCells(UndistortionGrid& g, std::vector<bool> filled) {
  const auto at = [&](int i, int j) { return i >= 0 && j >= 0 && i < g.nx && j < g.ny && filled[j * g.nx + i]; };
  for (;;) {
    std::vector<int> ring;
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i)
        for (int d = 0; d < 9 && !filled[j * g.nx + i]; ++d)
          if (d != 4 && at(i + d % 3 - 1, j + d / 3 - 1)) {
            ring.push_back(j * g.nx + i);
            break;
          }
    if (ring.empty()) return;
    for (int c : ring) {
      const int i = c % g.nx, j = c / g.nx;
      for (int k = 0; k < static_cast<int>(g.raw_nodes.size()); ++k) {
        double sum = 0, error = 0;
        int count = 0;
        for (int d = 0; d < 9; ++d) {
          const int di = d % 3 - 1, dj = d / 3 - 1;
          if (d == 4 || !at(i + di, j + dj)) continue;
          const double next = g.correction[g.Index(k, j + dj, i + di)];
          sum += at(i + 2 * di, j + 2 * dj) ? 2 * next - g.correction[g.Index(k, j + 2 * dj, i + 2 * di)] : next;
          error = std::max(error, 2.0 * g.std_error[g.Index(k, j + dj, i + di)]);
          ++count;
        }
        g.correction[g.Index(k, j, i)] = static_cast<float>(sum / count);
        g.std_error[g.Index(k, j, i)] = static_cast<float>(error);
      }
    }
    for (int c : ring) filled[c] = true;
  }
}

// What a snapshot adds to a grid's frame: its tilt and the extent of its
// pixels in the image and in raw.
struct SnapshotExtent {
  double tilt_deg = 0, x_min = 1e9, x_max = -1e9, y_min = 1e9, y_max = -1e9, raw_lo = 1e9, raw_hi = -1e9;
};

SnapshotExtent ExtentOf(const PlanarSnapshot& s) {
  SnapshotExtent e{s.tilt_deg};
  for (const auto& p : s.inliers) {
    e.x_min = std::min(e.x_min, p.x), e.x_max = std::max(e.x_max, p.x);
    e.y_min = std::min(e.y_min, p.y), e.y_max = std::max(e.y_max, p.y);
    e.raw_lo = std::min(e.raw_lo, p.raw), e.raw_hi = std::max(e.raw_hi, p.raw);
  }
  return e;
}

// The grid's frame (cells, truth, image extent, raw nodes) over the
// snapshots but `left_out`, with no correction yet.
UndistortionGrid Frame(const UndistortionGridOptions& options, const std::vector<SnapshotExtent>& extents,
                       std::size_t left_out = SIZE_MAX) {
  UndistortionGrid g;
  g.nx = options.cells_x;
  g.ny = options.cells_y;
  g.method = options.method;
  g.x_min = g.y_min = 1e9;
  g.x_max = g.y_max = -1e9;
  double raw_lo = 1e9, raw_hi = -1e9;
  for (std::size_t k = 0; k < extents.size(); ++k) {
    if (k == left_out) continue;
    const SnapshotExtent& e = extents[k];
    g.max_tilt_deg = std::max(g.max_tilt_deg, e.tilt_deg);
    g.x_min = std::min(g.x_min, e.x_min), g.x_max = std::max(g.x_max, e.x_max);
    g.y_min = std::min(g.y_min, e.y_min), g.y_max = std::max(g.y_max, e.y_max);
    raw_lo = std::min(raw_lo, e.raw_lo), raw_hi = std::max(raw_hi, e.raw_hi);
  }
  if (g.max_tilt_deg > options.max_square_tilt_deg) g.method = TrueRawMethod::kOwnPlane;
  for (int k = 0; k < options.raw_nodes; ++k)
    g.raw_nodes.push_back(raw_lo + (raw_hi - raw_lo) * k / (options.raw_nodes - 1));
  return g;
}

// The snapshots' cells (as CellPoints gives them) interpolated onto the frame's lattice.
UndistortionGrid Interpolated(const UndistortionGridOptions& options, UndistortionGrid g,
                              const std::vector<std::vector<CellPoint>>& cells) {
  const std::size_t nodes = g.raw_nodes.size() * cells.size();
  g.correction.assign(nodes, 0.f);
  g.std_error.assign(nodes, 0.f);
  g.supported.assign(nodes, 0);
  std::vector<bool> filled(cells.size());
  for (int j = 0; j < g.ny; ++j) {
    for (int i = 0; i < g.nx; ++i) {
      const auto& points = cells[static_cast<std::size_t>(j * g.nx + i)];
      if (points.empty()) continue;
      filled[static_cast<std::size_t>(j * g.nx + i)] = true;
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
  FillEmptyCells(g, std::move(filled));
  return g;
}

std::vector<SnapshotExtent> ExtentsOf(const std::vector<PlanarSnapshot>& snapshots) {
  std::vector<SnapshotExtent> extents;
  for (const auto& s : snapshots) extents.push_back(ExtentOf(s));
  return extents;
}

// Whether two frames put every pixel in the same cell with the same truth.
bool SameCells(const UndistortionGrid& a, const UndistortionGrid& b) {
  return a.method == b.method && a.x_min == b.x_min && a.x_max == b.x_max && a.y_min == b.y_min && a.y_max == b.y_max;
}

Rejection TooFewSnapshots(std::size_t found) {
  return Rejection{"undistortion_grid", "needs at least 2 clean planar snapshots, found " + std::to_string(found)};
}

}  // namespace

StageResult<UndistortionGrid> RunUndistortionGridBuild(const UndistortionGridOptions& options,
                                                       const std::vector<PlanarSnapshot>& snapshots) {
  if (snapshots.size() < 2) return TooFewSnapshots(snapshots.size());
  const UndistortionGrid frame = Frame(options, ExtentsOf(snapshots));
  std::vector<SnapshotPoints> points;
  for (const auto& s : snapshots) points.push_back(PointsOf(options, frame, s));
  return Interpolated(options, frame, CellPoints(points));
}

std::vector<StageResult<UndistortionGrid>> RunUndistortionGridHoldOuts(const UndistortionGridOptions& options,
                                                                       const std::vector<PlanarSnapshot>& snapshots) {
  const std::size_t n = snapshots.size();
  if (n < 3) return std::vector<StageResult<UndistortionGrid>>(n, TooFewSnapshots(n == 0 ? 0 : n - 1));
  const std::vector<SnapshotExtent> extents = ExtentsOf(snapshots);
  const UndistortionGrid whole = Frame(options, extents);
  std::vector<SnapshotPoints> points(n);
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t k) { points[k] = PointsOf(options, whole, snapshots[k]); });
  std::vector<StageResult<UndistortionGrid>> grids(n, TooFewSnapshots(0));
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t held) {
    const UndistortionGrid frame = Frame(options, extents, held);
    if (SameCells(frame, whole)) {
      grids[held] = Interpolated(options, frame, CellPoints(points, held));
      return;
    }
    // Without this snapshot the image extent or the walls' truth changes
    // (it was the only tilted wall, or reached furthest into a corner):
    // every other snapshot's cells are summed again in the new frame.
    std::vector<SnapshotPoints> others;
    for (std::size_t k = 0; k < n; ++k)
      if (k != held) others.push_back(PointsOf(options, frame, snapshots[k]));
    grids[held] = Interpolated(options, frame, CellPoints(others));
  });
  return grids;
}

bool UndistortionGridOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .AtLeast(cells_x, 1, "cells_x")
      .AtLeast(cells_y, 1, "cells_y")
      .AtLeast(raw_nodes, 2, "raw_nodes")
      .AtLeast(max_square_tilt_deg, 0, "max_square_tilt_deg")
      .AtLeast(min_pixels_per_cell, 1, "min_pixels_per_cell")
      .valid();
}

}  // namespace speckle
