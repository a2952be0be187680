#include "formats/pcd.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <cstring>

namespace speckle::formats {

namespace {

std::uint32_t PackedRgb(const std::uint8_t* rgb) {
  return (std::uint32_t{rgb[0]} << 16) | (std::uint32_t{rgb[1]} << 8) | rgb[2];
}

}  // namespace

std::string PcdFile(const apply::OrganizedCloud& cloud, PcdEncoding encoding) {
  const bool colour = !cloud.rgb.empty();
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  std::string out = fmt::format(
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z{}\nSIZE 4 4 4{}\nTYPE F F F{}\n"
      "COUNT 1 1 1{}\nWIDTH {}\nHEIGHT {}\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {}\nDATA {}\n",
      colour ? " rgb" : "", colour ? " 4" : "", colour ? " U" : "", colour ? " 1" : "", cloud.width, cloud.height, n,
      encoding == PcdEncoding::kBinary ? "binary" : "ascii");
  if (encoding == PcdEncoding::kBinary) {
    // Point records, little-endian (as every machine we build for).
    const std::size_t record = colour ? 16 : 12;
    const std::size_t start = out.size();
    out.resize(start + n * record);
    char* at = out.data() + start;
    for (std::size_t p = 0; p < n; ++p, at += record) {
      std::memcpy(at, &cloud.xyz[3 * p], 12);
      if (colour) {
        const std::uint32_t packed = PackedRgb(&cloud.rgb[3 * p]);
        std::memcpy(at + 12, &packed, 4);
      }
    }
    return out;
  }
  fmt::memory_buffer text;
  for (std::size_t p = 0; p < n; ++p) {
    // {} is the shortest text that reads back to the same float; NaN is "nan", as PCL writes it.
    fmt::format_to(std::back_inserter(text), "{} {} {}", cloud.xyz[3 * p], cloud.xyz[3 * p + 1], cloud.xyz[3 * p + 2]);
    if (colour) fmt::format_to(std::back_inserter(text), " {}", PackedRgb(&cloud.rgb[3 * p]));
    text.push_back('\n');
  }
  return out + fmt::to_string(text);
}

}  // namespace speckle::formats
