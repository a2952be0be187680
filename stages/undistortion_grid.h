#pragma once
// Stage 8: the undistortion interpolator g(r, x, y) -> r' (thesis chapter 4).
// Every inlier pixel of every cleaned snapshot is a sample (r, x, y) -> the
// snapshot's true raw value r'. Per image cell the samples' mean raw values
// of the snapshots are interpolated linearly along r, and the result is
// resampled on a regular lattice. The lattice keeps its region of support (r
// between the cell's nearest and farthest snapshot) and a standard error per
// node, so a user sees where it extrapolates.
#include <vector>

#include "stages/planar_cleanup.h"
#include "stages/records.h"

namespace speckle {

struct UndistortionGridOptions {
  int cells_x = 32, cells_y = 24;
  int raw_nodes = 48;
  TrueRawMethod method = TrueRawMethod::kHyperboloid;
  // When a wall is tilted more than this from square to the sensor, every
  // wall's truth is its own tilted plane (TrueRawMethod::kOwnPlane) instead.
  double max_square_tilt_deg = 0.5;
  int min_pixels_per_cell = 4;
};

struct UndistortionGrid {
  double x_min = 0, x_max = 0, y_min = 0, y_max = 0;  // normalized coordinates covered
  int nx = 0, ny = 0;
  std::vector<double> raw_nodes;                      // increasing
  // [raw node][y cell][x cell], row-major: the correction r' - r.
  std::vector<float> correction;
  std::vector<float> std_error;
  std::vector<std::uint8_t> supported;
  TrueRawMethod method = TrueRawMethod::kHyperboloid;  // the one used (see max_square_tilt_deg)
  double max_tilt_deg = 0;                             // the most tilted wall's tilt

  std::size_t Index(int k, int j, int i) const { return (static_cast<std::size_t>(k) * ny + j) * nx + i; }
  // r' for a raw value seen at normalized (x, y): trilinear, clamped.
  double Apply(double raw, double x, double y) const;
  // Share of nodes inside the region of support.
  double SupportedShare() const;
};

StageResult<UndistortionGrid> RunUndistortionGridBuild(const UndistortionGridOptions& options,
                                                       const std::vector<PlanarSnapshot>& snapshots);

}  // namespace speckle
