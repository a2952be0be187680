#pragma once
// A colour bar with its scale and a caption under an image map (check's
// error map, compare's difference maps), so the PNG reads on its own when it
// is mailed or opened without its page.
#include <opencv2/core.hpp>

#include <string>

namespace speckle {

struct MapLegend {
  cv::Mat bar;                    // 1 x N, CV_8UC3: the map's colours from its low end to its high end
  std::string low, middle, high;  // written under the bar's ends and middle
  std::string caption;            // what the colours are, and what black is
};

// The map with the legend drawn in a white band beneath it (at least 480 px wide).
cv::Mat WithLegend(const cv::Mat& map, const MapLegend& legend);

}  // namespace speckle
