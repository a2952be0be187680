#pragma once
// Which two other frames give a frame's rate of change (of its board's
// position, of its raw values): its neighbours either side, else the next
// two, else the previous two. Not the frame itself where others can: its
// own measurement error would pass for motion, and a delay fitted on the
// rate would then explain that error. In a run of two frames (a pose whose
// third frame was rejected) the pair itself (RatePair): left without a
// rate, such a frame kept its whole capture-time offset (the hunt's
// capture_time_offset seed 8: 2.8 raw on each of two frames).
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

// RateNeighbours, else the frame and its one close neighbour in the run.
inline std::optional<std::pair<std::size_t, std::size_t>> RatePair(const std::vector<double>& times,
                                                                   const std::vector<bool>& usable, std::size_t i,
                                                                   double max_gap_s) {
  if (auto pair = RateNeighbours(times, usable, i, max_gap_s)) return pair;
  const auto close = [&](std::size_t a, std::size_t b) {
    return b < times.size() && usable[a] && usable[b] && times[b] - times[a] > 0 && times[b] - times[a] <= max_gap_s;
  };
  if (close(i, i + 1)) return std::pair<std::size_t, std::size_t>(i, i + 1);
  if (i > 0 && close(i - 1, i)) return std::pair<std::size_t, std::size_t>(i - 1, i);
  return std::nullopt;
}

}  // namespace speckle
