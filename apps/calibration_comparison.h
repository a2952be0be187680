#pragma once
// compare's comparison of two calibrations of a depth camera: at each chosen
// depth, the raw value that calibration A reads as that depth over the
// image (its median), then the point each calibration makes of that same
// raw value at every pixel (its depth from the model, its place across the
// image from the depth camera). Each calibration's sigma for that point is
// its depth sigma at that depth (its report.json's, stated at the image
// centre, shaped over the image by its model's covariance) with the sideways
// sigma its depth camera's stated covariance (focal lengths, principal point,
// lens) gives that pixel's ray at that depth.
//
// The map is the distance over sigma A + sigma B, as mrcal draws two models'
// difference. The verdict judges the distance by the difference's own sigma,
// sqrt(sigma A^2 + sigma B^2): two independent calibrations whose sigmas are
// honest part by more than sigma A + sigma B at a pixel 16 % of the time at
// equal sigmas (up to 32 % when one dominates), so a verdict on that sum
// calls honest, tight calibrations different about one time in three over
// three depths (bench/results/compare.md). Beyond 3 of the difference's sigma
// happens 0.27 % of the time; a calibration's error is a few parameters
// shared by every pixel, so that is also about how often a whole depth is
// judged different by chance.
#include <array>
#include <string>
#include <vector>

#include "apply/depth_calibration.h"
#include "apply/point_measure.h"

namespace speckle {

struct ComparedCalibration {
  apply::DepthCalibration calibration;
  apply::DepthSigmaTable sigmas;  // empty: its report states none
  // The depth camera's fx, fy, cx, cy, k1, k2, p1, p2, k3 covariance, row-major: calibration.json's, or
  // its sigmas squared on the diagonal where it states none (all zero: taken as exact).
  std::array<double, 81> camera_covariance{};
  // Its model's parameter covariance (calibration.json's model.covariance), row-major; empty: none stated.
  std::vector<double> model_covariance;
};

struct DepthComparison {
  double depth_m = 0;                    // asked for
  double raw = 0;                        // the raw value A reads as depth_m, over the image's median
  int pixels = 0;                        // with a depth under both
  double median_depth_difference_m = 0;  // B - A along the axis
  double p95_abs_difference_m = 0, max_abs_difference_m = 0;  // the points' distance
  int max_u = 0, max_v = 0;                                   // where the largest difference is
  double sigma_a_m = 0, sigma_b_m = 0;                        // at depth_m (NaN when a report states none)
  bool extrapolated = false;                                  // depth_m outside either report's boards
  double share_beyond_sigma = 0;  // of the pixels, |B - A| > sigma A + sigma B (the points; the map's 1)
  double share_differing = 0;     // of the pixels, |B - A| > differ_sigmas sqrt(sigma A^2 + sigma B^2): the verdict's
  std::string worst_region;       // of a 3 x 3 split of the image, by mean |B - A| / (sigma A + sigma B)
  std::vector<float> ratio;       // per pixel |B - A| / (sigma A + sigma B), NaN without both
  int width = 0, height = 0;
  bool Differs(double share) const { return share_differing > share; }
};

struct ComparisonOptions {
  std::vector<double> depths_m = {0.8, 1.5, 3.0};
  double differ_sigmas = 3;    // a pixel differs beyond this many of its difference's sigma
  double differ_share = 0.05;  // a depth differs where more of its pixels than this differ
};

// Throws InputError when the two cannot be compared (depth image size or units differ).
std::vector<DepthComparison> CompareCalibrations(const ComparedCalibration& a, const ComparedCalibration& b,
                                                 const ComparisonOptions& options);

}  // namespace speckle
