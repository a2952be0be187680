#pragma once
// Regions of a raw depth image shared by the depthboard stages: a position
// gate around where the board should be, and the board grown inside it
// without crossing a depth step.
#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>

#include "schemas/depth_reading.h"

namespace speckle {

// The quadrilateral `corners` grown outward from its centre by `margin_px`,
// filled (CV_8U, 255 inside).
cv::Mat GatePolygon(cv::Size size, const std::array<Eigen::Vector2d, 4>& corners, double margin_px);

// CV_8U, 255 where `depth` (CV_16UC1) has no reading.
cv::Mat NoReadingMask(const cv::Mat& depth, const DepthReading& reading);

// `depth` as CV_32F on the raw-like scale of DepthReading::StepValue, so a
// step tolerance in raw units holds at every depth; no reading becomes 1e6
// (never within a step of a reading).
cv::Mat StepValues(const cv::Mat& depth, const DepthReading& reading);

// Pixels reachable from `seed` inside `gate` through valid neighbours whose raw
// values differ by at most `max_step_raw` (a tilted board, not a depth step).
cv::Mat GrowRegion(const cv::Mat& raw, const cv::Mat& gate, cv::Point seed, double max_step_raw,
                   const DepthReading& reading);

}  // namespace speckle
