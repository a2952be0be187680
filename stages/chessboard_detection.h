#pragma once
// Stage 1: the chessboard's interior corners in a colour or IR image.
#include <opencv2/core.hpp>
#include <string>

#include "stages/records.h"

namespace speckle {

struct ChessboardDetectionOptions {
  // Look at half resolution first (4x fewer pixels): refine large boards'
  // corners at full resolution, and search small boards again at full
  // resolution around where they were found; fall back to searching the
  // whole full-resolution image.
  bool try_half_resolution = true;
  // Below this mean square size (full-resolution pixels) the half-resolution
  // corners are too coarse to refine safely.
  double min_square_px_for_half = 14;
  int subpixel_window = 4;  // half-size of cornerSubPix's window
  // Images up to this wide are searched again at twice their resolution for
  // boards of 4-6 px squares; wider ones have larger squares.
  int max_width_to_upsample = 800;
  // False, naming the first broken rule's field in *why (schemas/option_check.h).
  bool IsValid(std::string* why) const;
};

struct ChessboardTrackingOptions {
  double max_motion_px = 1.5;          // a still board moves less than this between frames
  double max_homography_rms_px = 0.3;  // refined corners must still form a flat grid
  double min_corner_contrast = 25;     // grey levels between a corner's light and dark quadrants
  int subpixel_window = 4;
  // False, naming the first broken rule's field in *why (schemas/option_check.h).
  bool IsValid(std::string* why) const;
};

// `image`: CV_8UC3 RGB, CV_8UC1 grey, or CV_16UC1 IR (any bit depth).
// Corners come in a canonical order: row-major from the board's square (0, 0),
// which is the dark one whenever the two orientations can be told apart.
StageResult<ChessboardDetection> RunChessboardDetection(const ChessboardDetectionOptions& options,
                                                        const BoardGeometry& board, const cv::Mat& image);

}  // namespace speckle

namespace speckle {

// The same board in the next frame of a still pose: refine the previous
// frame's corners in this image instead of searching it (about 50x cheaper).
// Rejects when the board moved or the refined corners no longer form the
// board's grid; the caller then detects from scratch.
StageResult<ChessboardDetection> RunChessboardTracking(const ChessboardTrackingOptions& options,
                                                       const BoardGeometry& board, const cv::Mat& image,
                                                       const ChessboardDetection& previous);

}  // namespace speckle
