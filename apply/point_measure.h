#pragma once
// The thesis's measuring tool (appendix D.4): the 3-D distance and
// displacement between the points of two pixels of a corrected cloud.
#include <Eigen/Core>
#include <optional>

#include "apply/depth_corrector.h"

namespace speckle::apply {

struct PixelPoint {
  int u = 0, v = 0;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  // metres, depth camera
  int points_used = 0;                            // of the window's (2 window + 1)^2 pixels
};

// The point at pixel (u, v): the per-axis median of the points within
// `window` pixels of it (0: that pixel's own point), which tames the
// sensor's noise on a surface. nullopt when none of them has a point.
// Throws InputError when (u, v) is outside the image.
std::optional<PixelPoint> PointAt(const OrganizedCloud& cloud, int u, int v, int window);

struct Measurement {
  PixelPoint from, to;
  Eigen::Vector3d displacement;  // to - from
  double distance_m = 0;
};

// Throws InputError naming the pixel when it has no point.
Measurement Measure(const OrganizedCloud& cloud, int from_u, int from_v, int to_u, int to_v, int window);

}  // namespace speckle::apply
