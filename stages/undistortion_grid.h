#pragma once
// Stage 8: the undistortion interpolator g(r, x, y) -> r' (thesis chapter 4).
// Every inlier pixel of every cleaned snapshot is a sample (r, x, y) -> the
// snapshot's true raw value r'. Per image cell the samples' mean raw values
// of the snapshots are interpolated linearly along 1/r (beyond the cell's
// nearest and farthest snapshot, carried out along the same line), and the
// result is resampled on a regular lattice. The lattice keeps its region of
// support (r between the cell's nearest and farthest snapshot) and a standard
// error per node, so a user sees where it extrapolates.
#include <string>
#include <vector>

#include "model/undistortion_grid.h"
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
  // Between a cell's snapshots the correction is interpolated linearly in
  // 1/r (as billowing falls), else linearly in r (the thesis).
  bool interpolate_in_inverse_raw = true;
  // False, naming the first broken rule's field in *why (schemas/option_check.h).
  bool IsValid(std::string* why) const;
};

StageResult<UndistortionGrid> RunUndistortionGridBuild(const UndistortionGridOptions& options,
                                                       const std::vector<PlanarSnapshot>& snapshots);

// Element k: the grid RunUndistortionGridBuild makes from every snapshot but
// k, for holding each wall out of its own correction. The snapshots' cell
// sums are formed once and shared by the hold-outs whose frame (image extent,
// truth) is the whole set's: forming them again for every hold-out was
// O(snapshots^2) pixels, 21 of a 20-pose hunt session's 50 s.
std::vector<StageResult<UndistortionGrid>> RunUndistortionGridHoldOuts(const UndistortionGridOptions& options,
                                                                       const std::vector<PlanarSnapshot>& snapshots);

}  // namespace speckle
