#pragma once
// Colour and depth frames paired by their stamps, as the TUM RGB-D tools'
// associate.py does: of all colour/depth pairs at most `max_gap_ns` apart,
// the closest is taken first, then the closest of the rest, each frame in at
// most one pair. With frames at 30 Hz and a 20 ms gap this is each depth
// frame's nearest colour frame, as the fakenect import pairs them.
#include <cstdint>
#include <vector>

namespace speckle {

struct StampPair {
  int depth = -1;            // index into the depth stamps, -1 = none
  int colour = -1;           // index into the colour stamps, -1 = none
  std::int64_t time_ns = 0;  // the depth frame's stamp (the colour one's when alone)
};

// Every frame once, paired or alone, in time order. Stamps need not be sorted.
std::vector<StampPair> PairByStamp(const std::vector<std::int64_t>& depth_ns,
                                   const std::vector<std::int64_t>& colour_ns, std::int64_t max_gap_ns);

}  // namespace speckle
