#pragma once
// Reads one recording's frames in order, for the graph's input nodes.
// Recordings of one purpose read one after another (a session's walls added
// twice) number their frames on: `first_index` is this one's first.
#include <filesystem>

#include "pipeline/frame_work.h"
#include "recorder/recording_clock.h"
#include "recorder/recording_reader.h"

namespace speckle {

class FrameFeed {
 public:
  FrameFeed(const std::filesystem::path& path, RecordingPurpose recording, std::int64_t first_index = 0)
      : reader_(path),
        recording_(recording),
        first_index_(first_index),
        raw_source_(std::make_shared<RawSource>(path)) {}
  std::int64_t count() const { return reader_.frame_count(); }
  std::int64_t first_index() const { return first_index_; }
  Frame Next();  // null after the last frame
  const RecordingReader& reader() const { return reader_; }
  // Times count from the session's first frame (recording_clock.h).
  void StartClockAt(std::int64_t session_origin_ns) { clock_ = RecordingClock(session_origin_ns); }

 private:
  RecordingReader reader_;
  RecordingPurpose recording_;
  std::int64_t first_index_ = 0, next_ = 0;
  RecordingClock clock_;
  std::shared_ptr<const RawSource> raw_source_;
};

}  // namespace speckle
