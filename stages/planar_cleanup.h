#pragma once
// Stage 7: a planar snapshot (a wall facing the sensor) cleaned
// automatically, where the thesis cropped by hand: segment the wall
// (stages/wall_segmentation.h: the dominant plane in 3-D, grown into its
// connected region, so floor, ceiling, clutter and the invalid border fall
// away); reject a snapshot whose wall covers too little of the image or whose
// "wall" is tilted like a floor (a failed segmentation); fit the thesis's
// hyperboloid (Eq. 4.2) in r^2 to the wall; and estimate the snapshot's true
// raw value by the thesis's three methods, or, for a wall not quite square to
// the sensor, as the wall's own tilted plane.
#include <opencv2/core.hpp>
#include <string>

#include "model/undistortion_grid.h"
#include "stages/records.h"
#include "stages/wall_segmentation.h"

namespace speckle {

struct PlanarCleanupOptions {
  WallSegmentationOptions segmentation;
  // The wall must cover this share of the sampled image (inside the crop);
  // a far snapshot of a wide-angle lens sees the floor, the ceiling and the
  // lens's dark periphery too, and keeps about 40 %.
  double min_wall_share = 0.2;
  // Tilts up to this are square to the sensor within a user's aim.
  double max_square_tilt_deg = 3;
  // Beyond this the "wall" is a floor, a ceiling or an object seen
  // obliquely: the segmentation failed and the snapshot is rejected. In
  // between it is a real tilted wall, kept with its own plane.
  double max_wall_tilt_deg = 30;
  // A region scattering more than this about its smooth surface is not one
  // wall (noise and rounding give 0.5-1.5 raw).
  double max_wall_sigma_raw = 4;
  int centre_window_px = 40;  // side of the central window for the centre estimate
  // False, naming the first broken rule's field in *why (schemas/option_check.h).
  bool IsValid(std::string* why) const;
};

// kOwnPlane: each pixel's true raw value on the plane r = c0 + c1 x + c2 y
// fitted to the wall itself. A wall tilted by a degree shows a raw ramp that
// the thesis's single true value would hand to the undistortion grid as
// distortion; the plane keeps it out, at the cost of the distortion's own
// linear part, which no single wall can tell from a tilt.

struct PlanarSnapshot {
  int frame = 0;
  double true_raw_image_min = 0;
  double true_raw_hyperboloid = 0;
  double true_raw_centre_min = 0;
  // c0, c1, c2 of r = c0 + c1 x + c2 y (+ even terms in x, y for billowing) over the wall.
  Eigen::Vector3d raw_plane = Eigen::Vector3d::Zero();
  // The wall's tilt from square to the sensor, from raw_plane through the
  // nominal Kinect relation 1/z = -0.0030711 r + 3.3309 (1/m): the tilt is a
  // ratio, so the nominal slope's error of a few per cent hardly matters.
  double tilt_deg = 0;
  double fit_sigma_raw = 0;     // inlier scatter about the hyperboloid
  double raw_sigma_before = 0;  // scatter of the inliers' raw values (a flat wall: billowing + noise)
  int valid_pixels = 0;
  int inlier_pixels = 0;
  double wall_share = 0;  // inlier pixels over the sampled image
  // "square" (within max_square_tilt_deg) or "tilted_wall" (a real tilted
  // wall, kept with its own plane); a failed segmentation is rejected.
  std::string tilt_verdict;
  WallMask mask;                     // the segmented wall on the sampled grid
  std::vector<PlanarPixel> inliers;  // the wall's valid pixels
  // The true raw value at normalized coordinates (x, y); only kOwnPlane
  // depends on them.
  double TrueRaw(TrueRawMethod method, double x = 0, double y = 0) const;
};

// `segmented`, when given, receives the segmented wall whenever the
// segmentation found one, also when the snapshot is then rejected: the
// report shows a rejected wall's mask beside its reason.
StageResult<PlanarSnapshot> RunPlanarCleanup(const PlanarCleanupOptions& options, const CameraIntrinsics& depth,
                                             const cv::Mat& raw, const DepthReading& reading, int frame,
                                             WallMask* segmented = nullptr);

}  // namespace speckle
