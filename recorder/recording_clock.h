#pragma once
// Seconds since a recording's first frame, by the host clock of each pair's
// depth frame (its colour frame when it has no depth): the time covariate
// the fits' time effects (thermal drift) use, and what applying them reads.
#include <cstdint>

#include "recorder/frame_pair.h"

namespace speckle {

class RecordingClock {
 public:
  double Seconds(const FramePair& pair) {
    const std::int64_t host = pair.depth.valid() ? pair.depth.host_time_ns : pair.colour.host_time_ns;
    if (first_ns_ < 0 && host > 0) first_ns_ = host;
    return host > 0 ? (host - first_ns_) * 1e-9 : 0;
  }

 private:
  std::int64_t first_ns_ = -1;
};

}  // namespace speckle
