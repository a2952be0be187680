#include "stages/dark_border.h"

#include <opencv2/imgproc.hpp>

#include "stages/depth_region.h"

namespace speckle {

void AddReadings(const cv::Mat& raw, const DepthReading& reading, cv::Mat& ever_read) {
  if (raw.empty()) return;
  const cv::Mat read = ~NoReadingMask(raw, reading);
  if (ever_read.size() != raw.size())
    ever_read = read;
  else
    ever_read |= read;
}

cv::Mat DarkBorder(const cv::Mat& ever_read) {
  if (ever_read.empty()) return {};
  cv::Mat labels;
  const int count = cv::connectedComponents(ever_read == 0, labels, 4, CV_32S);
  std::vector<bool> at_edge(static_cast<std::size_t>(count), false);
  const auto mark = [&](int v, int u) { at_edge[static_cast<std::size_t>(labels.at<int>(v, u))] = true; };
  for (int u = 0; u < labels.cols; ++u) mark(0, u), mark(labels.rows - 1, u);
  for (int v = 0; v < labels.rows; ++v) mark(v, 0), mark(v, labels.cols - 1);
  at_edge[0] = false;  // label 0: pixels some frame read
  cv::Mat border(ever_read.size(), CV_8U);
  for (int v = 0; v < labels.rows; ++v) {
    const int* in = labels.ptr<int>(v);
    auto* out = border.ptr<std::uint8_t>(v);
    for (int u = 0; u < labels.cols; ++u) out[u] = at_edge[static_cast<std::size_t>(in[u])] ? 255 : 0;
  }
  return border;
}

}  // namespace speckle
