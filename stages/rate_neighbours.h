#pragma once
// Which two other frames give a frame's rate of change (of its board's
// position, of its raw values): its neighbours either side, else the next
// two, else the previous two. Never the frame itself: its own measurement
// error would pass for motion, and a delay fitted on the rate would then
// explain that error.
#include <optional>
#include <utility>
#include <vector>

namespace speckle {

// times: the frames' times in recording order; usable: which may be used. A
// run is consecutive usable frames at most max_gap_s apart. Returns the pair
// (earlier, later), or nothing when frame i's run has no two other frames.
inline std::optional<std::pair<std::size_t, std::size_t>> RateNeighbours(const std::vector<double>& times,
                                                                         const std::vector<bool>& usable, std::size_t i,
                                                                         double max_gap_s) {
  const auto n = static_cast<std::ptrdiff_t>(times.size());
  const auto linked = [&](std::ptrdiff_t a, std::ptrdiff_t b) {  // a to b, one run
    if (a < 0 || b >= n) return false;
    for (std::ptrdiff_t k = a; k < b; ++k) {
      const double dt = times[k + 1] - times[k];
      if (!usable[k] || !usable[k + 1] || dt <= 0 || dt > max_gap_s) return false;
    }
    return true;
  };
  const auto j = static_cast<std::ptrdiff_t>(i);
  if (linked(j - 1, j + 1)) return std::pair<std::size_t, std::size_t>(i - 1, i + 1);
  if (linked(j, j + 2)) return std::pair<std::size_t, std::size_t>(i + 1, i + 2);
  if (linked(j - 2, j)) return std::pair<std::size_t, std::size_t>(i - 2, i - 1);
  return std::nullopt;
}

}  // namespace speckle
