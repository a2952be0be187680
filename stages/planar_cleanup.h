#pragma once
// Stage 7: a planar snapshot (a wall square to the sensor) cleaned
// automatically, where the thesis cropped by hand: fit the thesis's
// hyperboloid (Eq. 4.2) in r^2 to the valid pixels with iterative outlier
// rejection, so floor, ceiling and clutter fall away; crop the periphery; and
// estimate the snapshot's true raw value by the thesis's three methods.
#include <opencv2/core.hpp>

#include "stages/records.h"

namespace speckle {

struct PlanarCleanupOptions {
  int crop_px = 8;              // ignore this many pixels at the image border
  int stride = 3;               // use every stride-th pixel: tens of thousands remain
  double inlier_sigmas = 4;     // inliers lie within this many robust sigmas of the fit
  double min_inlier_share = 0.3;
  int centre_window_px = 40;    // side of the central window for the centre estimate
};

enum class TrueRawMethod { kImageMinimum, kHyperboloid, kCentreMinimum };
const char* ToString(TrueRawMethod method);

struct PlanarPixel {
  double u, v, x, y, raw;
};

struct PlanarSnapshot {
  int frame = 0;
  double true_raw_image_min = 0;
  double true_raw_hyperboloid = 0;
  double true_raw_centre_min = 0;
  double fit_sigma_raw = 0;     // inlier scatter about the hyperboloid
  double raw_sigma_before = 0;  // scatter of the inliers' raw values (a flat wall: billowing + noise)
  int valid_pixels = 0;
  int inlier_pixels = 0;
  std::vector<PlanarPixel> inliers;
  double TrueRaw(TrueRawMethod method) const;
};

StageResult<PlanarSnapshot> RunPlanarCleanup(const PlanarCleanupOptions& options, const CameraIntrinsics& depth,
                                             const cv::Mat& raw, int frame);

}  // namespace speckle
