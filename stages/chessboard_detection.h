#pragma once
// Stage 1: the chessboard's interior corners in a colour or IR image.
#include <opencv2/core.hpp>

#include "stages/records.h"

namespace speckle {

struct ChessboardDetectionOptions {
  // Look at half resolution first (4x fewer pixels) and refine at full
  // resolution; fall back to full resolution when the board is not found.
  bool try_half_resolution = true;
  // Below this mean square size (full-resolution pixels) the half-resolution
  // corners are too coarse to refine safely.
  double min_square_px_for_half = 14;
  int subpixel_window = 4;  // half-size of cornerSubPix's window
};

// `image`: CV_8UC3 RGB, CV_8UC1 grey, or CV_16UC1 IR (any bit depth).
// Corners come in a canonical order: row-major from the board's square (0, 0),
// which is the dark one whenever the two orientations can be told apart.
StageResult<ChessboardDetection> RunChessboardDetection(const ChessboardDetectionOptions& options,
                                                        const BoardGeometry& board, const cv::Mat& image);

}  // namespace speckle
