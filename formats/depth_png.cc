#include "formats/depth_png.h"

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <stdexcept>

namespace speckle::formats {

std::vector<std::uint8_t> DepthPngMm(std::span<const float> depth_m, int width, int height) {
  cv::Mat mm(height, width, CV_16UC1);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const float z = depth_m[static_cast<std::size_t>(v) * width + u] * 1000.0f;
      mm.at<std::uint16_t>(v, u) =
          std::isfinite(z) && z >= 0.5f && z < 65535.5f ? static_cast<std::uint16_t>(std::lround(z)) : 0;
    }
  }
  std::vector<std::uint8_t> png;
  if (!cv::imencode(".png", mm, png)) throw std::runtime_error("OpenCV could not encode a 16-bit PNG");
  return png;
}

}  // namespace speckle::formats
