#pragma once
// The thesis's measuring tool (appendix D.4): the 3-D distance and
// displacement between the points of two pixels of a corrected cloud.
#include <Eigen/Core>
#include <optional>
#include <vector>

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

// The depth sigma a calibration states by depth (its report.json's
// depth_uncertainty rows), increasing in depth.
struct DepthSigmaTable {
  std::vector<double> depth_m, sigma_m;
  // Interpolated; beyond the rows the end row's relative sigma.
  double At(double depth) const;
  bool Covers(double depth) const;  // within the rows' depths
};

// The distance's standard deviation from the calibration's depth sigma at
// each end: each end moved along its ray by its sigma, both alike (a depth
// scale error, which most of a calibration's is) or each alone, whichever
// moves the distance more. The sensor's noise at the two pixels is not in it.
double DistanceSigma(const Measurement& m, const DepthSigmaTable& table);

}  // namespace speckle::apply
