#pragma once
// The board's size as the depth sensor itself measures it, against the size
// session.json's rig states (which is all the colour camera's scale rests
// on). The sensor triangulates with its projector's baseline B, the one
// length every sensor of the family shares. A board's apparent area in the
// depth image and its raw disparity then give its metric size without the
// depth camera's focal length or the raw offset c. For a board facing the
// camera at depth z, area_px = fx^2 A / z^2 and raw = c - 8 fx B / z, so
// raw = c - (8 B / sqrt(A)) sqrt(area_px): over the views, a line whose slope
// gives sqrt(A). A tilted board's terms come from its colour pose, whose
// turn and shape a wrong square size leaves as they are (PointOf). An
// outline fattened by a constant pixel or two (real structured-light edges)
// moves c, not the slope.
#include <optional>
#include <vector>

#include "stages/outline_calibration.h"
#include "stages/records.h"

namespace speckle {

struct BoardSizeInDepth {
  double measured_m = 0;  // sqrt(area) by the depth's triangulation with the family's baseline
  double sigma_m = 0;     // 1 sigma, from the line's scatter over the views
  double stated_m = 0;    // sqrt(width * height) of the rig's board
  int views = 0;          // views on the line (after outliers)
  double Ratio() const { return measured_m / stated_m; }
  // Beyond what the family's measured baselines allow by more than 3 sigma:
  // the board is not the size the rig says.
  bool OutsideFamily() const;
};

struct BoardSizeOptions {
  int min_poses = 6;         // still poses (the sigma leaves one out at a time)
  double min_raw_span = 40;  // the views' raw values must span this, or the slope is not measured
};

// `views` with outlines that are the chessboard's own edge, `depth` the
// depth camera (its lens undistorts the outlines; its focal length cancels)
// and `depth_from_colour` the rig's extrinsics, both in the rig's units.
// Nothing when too few still poses or too little spread in distance.
std::optional<BoardSizeInDepth> MeasureBoardSizeInDepth(const BoardSizeOptions& options, const BoardGeometry& board,
                                                        const std::vector<ExtrinsicsView>& views,
                                                        const CameraIntrinsics& depth,
                                                        const Eigen::Isometry3d& depth_from_colour);

}  // namespace speckle
