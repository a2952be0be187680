#include "recorder/sources/stamp_pairing.h"

#include <algorithm>
#include <cstdlib>
#include <tuple>

namespace speckle {

std::vector<StampPair> PairByStamp(const std::vector<std::int64_t>& depth_ns,
                                   const std::vector<std::int64_t>& colour_ns, std::int64_t max_gap_ns) {
  // Candidates within the gap: colour sorted by time, so a window per depth frame.
  std::vector<int> colour_order(colour_ns.size());
  for (std::size_t k = 0; k < colour_order.size(); ++k) colour_order[k] = static_cast<int>(k);
  std::stable_sort(colour_order.begin(), colour_order.end(), [&](int a, int b) { return colour_ns[a] < colour_ns[b]; });
  std::vector<std::tuple<std::int64_t, int, int>> candidates;  // gap, depth, colour
  for (std::size_t d = 0; d < depth_ns.size(); ++d) {
    auto it = std::lower_bound(colour_order.begin(), colour_order.end(), depth_ns[d] - max_gap_ns,
                               [&](int k, std::int64_t t) { return colour_ns[k] < t; });
    for (; it != colour_order.end() && colour_ns[*it] <= depth_ns[d] + max_gap_ns; ++it)
      candidates.emplace_back(std::llabs(colour_ns[*it] - depth_ns[d]), static_cast<int>(d), *it);
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<int> colour_of(depth_ns.size(), -1);
  std::vector<bool> colour_used(colour_ns.size(), false);
  for (const auto& [gap, d, c] : candidates) {
    if (colour_of[d] >= 0 || colour_used[c]) continue;
    colour_of[d] = c;
    colour_used[c] = true;
  }
  std::vector<StampPair> pairs;
  for (std::size_t d = 0; d < depth_ns.size(); ++d) pairs.push_back({static_cast<int>(d), colour_of[d], depth_ns[d]});
  for (std::size_t c = 0; c < colour_ns.size(); ++c)
    if (!colour_used[c]) pairs.push_back({-1, static_cast<int>(c), colour_ns[c]});
  std::stable_sort(pairs.begin(), pairs.end(),
                   [](const StampPair& a, const StampPair& b) { return a.time_ns < b.time_ns; });
  return pairs;
}

}  // namespace speckle
