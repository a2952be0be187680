#pragma once
// Corrected depth as a 16-bit PNG in millimetres (0: no point), the depth
// image format of ROS (16UC1) and of most RGB-D datasets. Pixels keep their
// place: the image is not resampled, so it pairs with the depth camera's
// distorted intrinsics (formats/camera_yaml.h).
#include <cstdint>
#include <span>
#include <vector>

namespace speckle::formats {

// `depth_m`: width x height depths along the optical axis, NaN where none.
// Depths beyond 65.535 m are written as 0.
std::vector<std::uint8_t> DepthPngMm(std::span<const float> depth_m, int width, int height);

}  // namespace speckle::formats
