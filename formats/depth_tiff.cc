#include "formats/depth_tiff.h"

#include <opencv2/imgcodecs.hpp>

#include <stdexcept>

namespace speckle::formats {

std::vector<std::uint8_t> DepthTiffM(std::span<const float> depth_m, int width, int height) {
  const cv::Mat metres(height, width, CV_32FC1, const_cast<float*>(depth_m.data()));
  std::vector<std::uint8_t> tiff;
  if (!cv::imencode(".tiff", metres, tiff)) throw std::runtime_error("OpenCV could not encode a 32-bit float TIFF");
  return tiff;
}

}  // namespace speckle::formats
