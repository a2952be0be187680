#include "formats/ply.h"

#include <fmt/format.h>

#include <cmath>
#include <cstring>

namespace speckle::formats {

std::string PlyFile(const apply::OrganizedCloud& cloud, const std::string& comment) {
  const bool colour = !cloud.rgb.empty();
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  std::size_t points = 0;
  for (std::size_t p = 0; p < n; ++p) points += std::isfinite(cloud.xyz[3 * p + 2]);
  std::string out = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment {}\nelement vertex {}\n"
      "property float x\nproperty float y\nproperty float z\n{}end_header\n",
      comment, points, colour ? "property uchar red\nproperty uchar green\nproperty uchar blue\n" : "");
  const std::size_t record = colour ? 15 : 12;
  std::size_t at = out.size();
  out.resize(at + points * record);
  for (std::size_t p = 0; p < n; ++p) {
    if (!std::isfinite(cloud.xyz[3 * p + 2])) continue;
    std::memcpy(&out[at], &cloud.xyz[3 * p], 12);
    if (colour) std::memcpy(&out[at + 12], &cloud.rgb[3 * p], 3);
    at += record;
  }
  return out;
}

}  // namespace speckle::formats
