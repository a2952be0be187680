#pragma once
// The depth camera's dark border over a session: the pixels no frame read
// that join the image's edge. A wide-angle adapter's dark corners and the
// sensor's invalid band are such pixels; a board that runs into them is cut
// there, and its depth outline is not the board's.
#include <opencv2/core.hpp>

#include "schemas/depth_reading.h"

namespace speckle {

// Counts `raw`'s readings into `ever_read` (CV_8U, 255 where any frame so far
// had a reading; created on the first frame).
void AddReadings(const cv::Mat& raw, const DepthReading& reading, cv::Mat& ever_read);

// CV_8U, 255 on the pixels `ever_read` never saw read that connect to the
// image's edge through such pixels; shadows and holes inside the view, and
// anything never read away from the edge, are left out. Empty for an empty
// `ever_read`.
cv::Mat DarkBorder(const cv::Mat& ever_read);

}  // namespace speckle
