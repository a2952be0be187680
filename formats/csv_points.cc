#include "formats/csv_points.h"

#include <fmt/format.h>

#include <cmath>

namespace speckle::formats {

std::string CsvPoints(const apply::OrganizedCloud& cloud) {
  const bool colour = !cloud.rgb.empty();
  fmt::memory_buffer text;
  fmt::format_to(std::back_inserter(text), "u,v,x_m,y_m,z_m{}\n", colour ? ",r,g,b" : "");
  for (int v = 0; v < cloud.height; ++v) {
    for (int u = 0; u < cloud.width; ++u) {
      const std::size_t p = static_cast<std::size_t>(v) * cloud.width + u;
      if (!std::isfinite(cloud.xyz[3 * p + 2])) continue;
      fmt::format_to(std::back_inserter(text), "{},{},{},{},{}", u, v, cloud.xyz[3 * p], cloud.xyz[3 * p + 1],
                     cloud.xyz[3 * p + 2]);
      if (colour)
        fmt::format_to(std::back_inserter(text), ",{},{},{}", cloud.rgb[3 * p], cloud.rgb[3 * p + 1],
                       cloud.rgb[3 * p + 2]);
      text.push_back('\n');
    }
  }
  return fmt::to_string(text);
}

}  // namespace speckle::formats
