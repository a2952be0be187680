#include "stages/still_frame_average.h"

#include "schemas/option_check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace speckle {

StageResult<cv::Mat> RunStillFrameAverage(const StillFrameAverageOptions& options, const std::vector<cv::Mat>& raws,
                                          const DepthReading& reading) {
  constexpr const char* kStage = "still_frame_average";
  constexpr std::size_t kMaxFrames = 64;
  if (raws.empty()) return Rejection{kStage, "no frames to average"};
  if (raws.size() > kMaxFrames) {
    return Rejection{kStage,
                     std::to_string(raws.size()) + " frames; at most " + std::to_string(kMaxFrames) + " are averaged"};
  }
  for (std::size_t k = 0; k < raws.size(); ++k) {
    if (raws[k].type() != CV_16UC1 || raws[k].size() != raws[0].size()) {
      return Rejection{kStage, "frame " + std::to_string(k) + " of the still pose is not a " +
                                   std::to_string(raws[0].cols) + "x" + std::to_string(raws[0].rows) +
                                   " 16-bit raw depth image"};
    }
  }
  const auto needed = static_cast<std::size_t>(std::max(1.0, std::ceil(options.min_valid_share * raws.size())));
  cv::Mat out(raws[0].size(), CV_16UC1);
  std::array<std::uint16_t, kMaxFrames> valid{};
  for (int v = 0; v < out.rows; ++v) {
    std::vector<const std::uint16_t*> rows;
    for (const cv::Mat& r : raws) rows.push_back(r.ptr<std::uint16_t>(v));
    auto* o = out.ptr<std::uint16_t>(v);
    for (int u = 0; u < out.cols; ++u) {
      std::size_t n = 0;
      for (const auto* row : rows)
        if (reading.IsReading(row[u])) valid[n++] = row[u];
      if (n < needed) {
        o[u] = reading.NoReadingValue();
        continue;
      }
      const auto middle = valid.begin() + static_cast<std::ptrdiff_t>(n / 2);
      std::nth_element(valid.begin(), middle, valid.begin() + static_cast<std::ptrdiff_t>(n));
      o[u] = *middle;
    }
  }
  return out;
}

bool StillFrameAverageOptions::IsValid(std::string* why) const {
  return OptionCheck(why).Share(min_valid_share, "min_valid_share").valid();
}

}  // namespace speckle
