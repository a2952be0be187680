#pragma once
// Regions of a raw depth image shared by the depthboard stages: a position
// gate around where the board should be, and the board grown inside it
// without crossing a depth step.
#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>

namespace speckle {

// The quadrilateral `corners` grown outward from its centre by `margin_px`,
// filled (CV_8U, 255 inside).
cv::Mat GatePolygon(cv::Size size, const std::array<Eigen::Vector2d, 4>& corners, double margin_px);

// Pixels reachable from `seed` inside `gate` through valid neighbours whose raw
// values differ by at most `max_step_raw` (a tilted board, not a depth step).
cv::Mat GrowRegion(const cv::Mat& raw, const cv::Mat& gate, cv::Point seed, double max_step_raw);

}  // namespace speckle
