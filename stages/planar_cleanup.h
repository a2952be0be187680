#pragma once
// Stage 7: a planar snapshot (a wall square to the sensor) cleaned
// automatically, where the thesis cropped by hand: fit the thesis's
// hyperboloid (Eq. 4.2) in r^2 to the valid pixels with iterative outlier
// rejection, so floor, ceiling and clutter fall away; crop the periphery; and
// estimate the snapshot's true raw value by the thesis's three methods, or,
// for a wall not quite square to the sensor, as the wall's own tilted plane.
#include <opencv2/core.hpp>

#include "model/undistortion_grid.h"
#include "stages/records.h"

namespace speckle {

struct PlanarCleanupOptions {
  int crop_px = 8;              // ignore this many pixels at the image border
  int stride = 3;               // use every stride-th pixel: tens of thousands remain
  double inlier_sigmas = 4;     // inliers lie within this many robust sigmas of the fit
  double min_inlier_share = 0.3;
  int centre_window_px = 40;    // side of the central window for the centre estimate
  DepthReading reading;  // the recording's units: which values are no reading
};

// kOwnPlane: each pixel's true raw value on the plane r = c0 + c1 x + c2 y
// fitted to the wall itself. A wall tilted by a degree shows a raw ramp that
// the thesis's single true value would hand to the undistortion grid as
// distortion; the plane keeps it out, at the cost of the distortion's own
// linear part, which no single wall can tell from a tilt.

struct PlanarPixel {
  double u, v, x, y, raw;
};

struct PlanarSnapshot {
  int frame = 0;
  double true_raw_image_min = 0;
  double true_raw_hyperboloid = 0;
  double true_raw_centre_min = 0;
  // c0, c1, c2 of r = c0 + c1 x + c2 y (+ radial terms for billowing) over the inliers.
  Eigen::Vector3d raw_plane = Eigen::Vector3d::Zero();
  // The wall's tilt from square to the sensor, from raw_plane through the
  // nominal Kinect relation 1/z = -0.0030711 r + 3.3309 (1/m): the tilt is a
  // ratio, so the nominal slope's error of a few per cent hardly matters.
  double tilt_deg = 0;
  double fit_sigma_raw = 0;     // inlier scatter about the hyperboloid
  double raw_sigma_before = 0;  // scatter of the inliers' raw values (a flat wall: billowing + noise)
  int valid_pixels = 0;
  int inlier_pixels = 0;
  std::vector<PlanarPixel> inliers;
  // The true raw value at normalized coordinates (x, y); only kOwnPlane
  // depends on them.
  double TrueRaw(TrueRawMethod method, double x = 0, double y = 0) const;
};

StageResult<PlanarSnapshot> RunPlanarCleanup(const PlanarCleanupOptions& options, const CameraIntrinsics& depth,
                                             const cv::Mat& raw, int frame);

}  // namespace speckle
