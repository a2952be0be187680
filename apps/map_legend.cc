#include "apps/map_legend.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>

namespace speckle {
namespace {

constexpr int kBand = 58, kMargin = 10, kBarHeight = 14;
constexpr double kFontScale = 0.42;

void Label(cv::Mat& image, const std::string& text, int x, int y, double align) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, kFontScale, 1, &baseline);
  const int left = std::clamp(x - static_cast<int>(align * size.width), 2, std::max(2, image.cols - size.width - 2));
  cv::putText(image, text, {left, y}, cv::FONT_HERSHEY_SIMPLEX, kFontScale, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
}

}  // namespace

cv::Mat WithLegend(const cv::Mat& map, const MapLegend& legend) {
  const int width = std::max(map.cols, 480);
  cv::Mat out(map.rows + kBand, width, CV_8UC3, cv::Scalar(255, 255, 255));
  out(cv::Rect(0, 0, width, map.rows)).setTo(cv::Scalar(128, 128, 128));  // beside a narrow map: no colour of its scale
  map.copyTo(out(cv::Rect(0, 0, map.cols, map.rows)));
  const int top = map.rows + 6, bar_width = width - 2 * kMargin;
  cv::Mat bar;
  cv::resize(legend.bar, bar, cv::Size(bar_width, kBarHeight), 0, 0, cv::INTER_LINEAR);
  bar.copyTo(out(cv::Rect(kMargin, top, bar_width, kBarHeight)));
  const int labels = top + kBarHeight + 14;
  Label(out, legend.low, kMargin, labels, 0);
  Label(out, legend.middle, kMargin + bar_width / 2, labels, 0.5);
  Label(out, legend.high, kMargin + bar_width, labels, 1);
  Label(out, legend.caption, kMargin, labels + 17, 0);
  return out;
}

}  // namespace speckle
