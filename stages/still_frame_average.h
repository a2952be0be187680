#pragma once
// Optional step before depthboard quad extraction (thesis figure 3.3): the
// raw frames of a still board are combined so the board's outline stops
// flickering between board and background from frame to frame.
//
// The combination is a per-pixel median of the valid readings, not a mean: a
// pixel on the board's edge that reads board in three frames and background in
// two keeps the board's value instead of a blend that belongs to neither, so
// the outline lands where the board covers the pixel most of the time.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "stages/records.h"

namespace speckle {

struct StillFrameAverageOptions {
  // A pixel valid in fewer than this share of the frames stays invalid.
  double min_valid_share = 0.5;
  // False, naming the first broken rule's field in *why (schemas/option_check.h).
  bool IsValid(std::string* why) const;
};

// `raws`: CV_16UC1 frames of one still pose, all the same size, in
// `reading`'s units. Returns their per-pixel median (CV_16UC1), or a rejection when the
// frames do not match.
StageResult<cv::Mat> RunStillFrameAverage(const StillFrameAverageOptions& options, const std::vector<cv::Mat>& raws,
                                          const DepthReading& reading);

}  // namespace speckle
