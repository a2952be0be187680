#pragma once
// Depth as a 32-bit float TIFF in metres, NaN where there is no reading:
// REP 118's 32FC1 image as a file (OpenCV, Pillow, tifffile and GDAL read it).
#include <cstdint>
#include <span>
#include <vector>

namespace speckle::formats {

// `depth_m`: width x height depths along the optical axis, row-major, NaN where none.
std::vector<std::uint8_t> DepthTiffM(std::span<const float> depth_m, int width, int height);

}  // namespace speckle::formats
