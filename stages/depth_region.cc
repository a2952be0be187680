#include "stages/depth_region.h"

#include <opencv2/imgproc.hpp>

namespace speckle {

cv::Mat GatePolygon(cv::Size size, const std::array<Eigen::Vector2d, 4>& corners, double margin_px) {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const auto& c : corners) centre += c / 4;
  std::vector<cv::Point> polygon;
  for (const auto& c : corners) {
    const Eigen::Vector2d grown = c + (c - centre).normalized() * margin_px;
    polygon.emplace_back(cvRound(grown.x()), cvRound(grown.y()));
  }
  cv::Mat gate(size, CV_8U, cv::Scalar(0));
  cv::fillConvexPoly(gate, polygon, 255);
  return gate;
}

cv::Mat NoReadingMask(const cv::Mat& depth, const DepthReading& reading) {
  cv::Mat none(depth.size(), CV_8U);
  for (int v = 0; v < depth.rows; ++v) {
    const auto* in = depth.ptr<std::uint16_t>(v);
    auto* out = none.ptr<std::uint8_t>(v);
    for (int u = 0; u < depth.cols; ++u) out[u] = reading.IsReading(in[u]) ? 0 : 255;
  }
  return none;
}

cv::Mat StepValues(const cv::Mat& depth, const DepthReading& reading) {
  cv::Mat values(depth.size(), CV_32F);
  for (int v = 0; v < depth.rows; ++v) {
    const auto* in = depth.ptr<std::uint16_t>(v);
    auto* out = values.ptr<float>(v);
    for (int u = 0; u < depth.cols; ++u)
      out[u] = reading.IsReading(in[u]) ? static_cast<float>(reading.StepValue(in[u])) : 1e6f;
  }
  return values;
}

cv::Mat GrowRegion(const cv::Mat& raw, const cv::Mat& gate, cv::Point seed, double max_step_raw,
                   const DepthReading& reading) {
  const cv::Mat values = StepValues(raw, reading);  // no reading: never part of the region
  cv::Mat blocked;                                  // floodFill's mask: non-zero blocks, 2 px larger
  cv::copyMakeBorder(~gate, blocked, 1, 1, 1, 1, cv::BORDER_CONSTANT, 255);
  const float step = static_cast<float>(max_step_raw);
  cv::floodFill(values, blocked, seed, cv::Scalar(), nullptr, cv::Scalar(step), cv::Scalar(step),
                4 | cv::FLOODFILL_MASK_ONLY | (128 << 8));
  return blocked(cv::Rect(1, 1, raw.cols, raw.rows)) == 128;
}

}  // namespace speckle
