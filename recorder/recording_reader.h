#pragma once
// Reads and validates one recording. Every check failure is an InputError
// naming the file and the dataset or attribute, and what was expected.
#include <H5Cpp.h>

#include <filesystem>
#include <memory>
#include <string>

#include "recorder/frame_pair.h"
#include "recorder/recording_header.h"

namespace speckle {

// Which streams' images ReadFrame decodes (bits; clocks are always read).
enum StreamBits : unsigned { kColourStream = 1u, kDepthStream = 2u, kIrStream = 4u, kAllStreams = 7u };

class RecordingReader {
 public:
  explicit RecordingReader(const std::filesystem::path& path);
  ~RecordingReader();

  const RecordingHeader& header() const { return header_; }
  std::int64_t frame_count() const { return frame_count_; }
  // False when the writer never closed the file (killed recorder): it was
  // opened with SWMR read access and holds the frames up to the last flush.
  bool closed_cleanly() const { return closed_cleanly_; }
  // Non-empty when datasets of a not-cleanly-closed file had different
  // lengths and the shortest was used.
  const std::string& truncation_note() const { return truncation_note_; }

  // Images of streams the recording lacks, or frames flagged invalid, or not
  // asked for in `streams`, are empty.
  FramePair ReadFrame(std::int64_t index, unsigned streams = kAllStreams) const;
  std::vector<AccelSample> ReadAccel() const;
  // Per-stream clocks and validity for all frames, without reading images.
  struct StreamClock {
    std::vector<std::uint8_t> valid;
    std::vector<std::uint64_t> device_timestamp;
    std::vector<std::int64_t> host_time_ns;
  };
  StreamClock ReadClock(int stream) const;  // 0 colour, 1 depth, 2 ir

  const std::filesystem::path& path() const { return path_; }

 private:
  void RefuseRawAbove11Bits(const cv::Mat& raw, std::int64_t index) const;
  struct Impl;
  std::filesystem::path path_;
  std::unique_ptr<Impl> impl_;
  RecordingHeader header_;
  std::int64_t frame_count_ = 0;
  bool closed_cleanly_ = true;
  std::string truncation_note_;
};

}  // namespace speckle
