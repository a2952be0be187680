#pragma once
// Seconds since the session's first frame, by the host clock of each pair's
// depth frame (its colour frame when it has no depth): the time covariate
// the fits' time effects (thermal drift) use, and what applying them reads.
// A session's recordings share the host's clock, and the sensor warms up
// from the first of them on: a wall recording made 20 minutes after the
// boards is 20 minutes into the drift, not at its start.
#include <cstdint>
#include <vector>

#include "recorder/frame_pair.h"
#include "recorder/recording_reader.h"

namespace speckle {

class RecordingClock {
 public:
  // `origin_ns`: the session's first host time (FirstHostTimeNs); < 0: this
  // recording's own first frame (a recording without a session).
  explicit RecordingClock(std::int64_t origin_ns = -1) : origin_ns_(origin_ns) {}
  double Seconds(const FramePair& pair) {
    const std::int64_t host = pair.depth.valid() ? pair.depth.host_time_ns : pair.colour.host_time_ns;
    if (origin_ns_ < 0 && host > 0) origin_ns_ = host;
    return host > 0 ? (host - origin_ns_) * 1e-9 : 0;
  }

 private:
  std::int64_t origin_ns_ = -1;
};

// The earliest host time of any frame of these recordings (colour or depth),
// -1 when none has one.
std::int64_t FirstHostTimeNs(const std::vector<const RecordingReader*>& recordings);

}  // namespace speckle
