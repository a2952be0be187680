#pragma once
// The wall in one planar snapshot. A wide-angle view of a wall in a room also
// sees the floor, the ceiling and clutter; taken as wall they bend the wall's
// fitted truth and the undistortion grid learns the room instead of the optics.
//
// 1. The dominant plane in 3-D: MSAC over the central part of the image (the
//    user aims the sensor at the wall; there billowing is a few raw units),
//    on points unprojected through the depth camera with the nominal Kinect
//    relation. Any reciprocal raw-to-depth relation keeps a plane a plane
//    (1/z is linear in raw and, on a plane, in x and y), so the nominal one
//    finds the same plane as the calibrated one; residuals are measured in raw
//    units, where the sensor's noise is.
// 2. Grown over the whole image by refitting the wall as a quadric in r^2
//    (r^2 = quadratic in x, y: exact for a tilted plane under the thesis's
//    billowing, Eq. 4.2), keeping pixels within a few robust sigmas, and
//    keeping only the connected region that holds the MSAC seed.
// The floor, ceiling and clutter lie off that surface by far more than the
// noise, the invalid border has no reading: all are left out.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "schemas/depth_reading.h"
#include "stages/records.h"

namespace speckle {

struct WallSegmentationOptions {
  int crop_px = 8;               // ignore this many pixels at the image border
  int stride = 3;                // sample every stride-th pixel
  double seed_half_width = 0.2;  // the MSAC region: |x|, |y| below this (normalized coordinates)
  int msac_iterations = 300;
  double msac_tolerance_raw = 8;   // noise plus the billowing within the seed region
  double inlier_sigmas = 4;        // the grown wall lies within this many robust sigmas
  double min_tolerance_raw = 1.5;  // never narrower: rounding to whole raw units
  int grow_rounds = 6;
  // False, naming the first broken rule's field in *why (schemas/option_check.h).
  bool IsValid(std::string* why) const;
};

// The sampled pixel grid: cell (i, j) is pixel (crop + i * stride, crop + j * stride).
struct WallMask {
  int crop_px = 0, stride = 1, cols = 0, rows = 0;
  std::vector<std::uint8_t> wall;     // rows * cols, 1 = wall
  std::vector<std::uint8_t> reading;  // rows * cols, 1 = the pixel has a reading (wall or not)
  int Count() const;
  // Run lengths over the row-major cells, alternating 0 and 1, starting with
  // 0 (a first run of 0 when cell 0 is 1): of `wall`, or of `reading` (the
  // report tells floor, ceiling and clutter from no reading by it).
  std::vector<int> RunLengths() const;
  std::vector<int> ReadingRunLengths() const;
};

struct PlanarPixel {
  double u, v, x, y, raw;
};

struct WallSegmentation {
  WallMask mask;
  std::vector<PlanarPixel> wall_pixels;  // the valid pixels of the mask
  int sampled_pixels = 0;                // every cell of the grid, valid or not
  int valid_pixels = 0;                  // cells with a reading
  double sigma_raw = 0;                  // robust scatter of the wall about its fitted surface
};

// Rejected (with the reason) when no plane dominates the image's centre.
StageResult<WallSegmentation> SegmentWall(const WallSegmentationOptions& options, const CameraIntrinsics& depth,
                                          const cv::Mat& raw, const DepthReading& reading, int frame);

}  // namespace speckle
