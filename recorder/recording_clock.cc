#include "recorder/recording_clock.h"

#include <algorithm>

namespace speckle {

std::int64_t FirstHostTimeNs(const std::vector<const RecordingReader*>& recordings) {
  std::int64_t first = -1;
  for (const RecordingReader* r : recordings) {
    for (const int stream : {0, 1}) {  // colour, depth
      const RecordingReader::StreamClock clock = r->ReadClock(stream);
      for (std::size_t i = 0; i < clock.host_time_ns.size(); ++i) {
        const std::int64_t host = clock.host_time_ns[i];
        if (i < clock.valid.size() && clock.valid[i] && host > 0) first = first < 0 ? host : std::min(first, host);
      }
    }
  }
  return first;
}

}  // namespace speckle
