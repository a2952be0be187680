#pragma once
// Writes one recording (HDF5, layout in schemas/session_format.md) so that a
// killed process loses at most the frames since the last flush:
//  - the file is created exclusively (never overwrites) with the latest file
//    format and switched to SWMR mode, in which HDF5 orders its metadata
//    writes so the on-disk file is always consistent;
//  - every frame is one chunk, compressed on the caller's thread (see
//    ChunkCodec) and written with H5Dwrite_chunk;
//  - the file is flushed at least every `flush_interval`.
// A reader opens a file whose writer died with SWMR read access; see
// RecordingReader.
#include <H5Cpp.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>

#include "recorder/chunk_codec.h"
#include "recorder/frame_pair.h"
#include "recorder/recording_header.h"

namespace speckle {

struct RecordingWriterOptions {
  Codec codec = Codec::kSzip;
  int deflate_level = 1;  // only for Codec::kDeflate; 1 is fast, 9 is small
  // Longest time between flushes: the most a killed recorder can lose.
  std::chrono::milliseconds flush_interval{500};
};

// A frame whose images are already compressed; made by Encode on any thread.
struct EncodedFramePair {
  FramePair meta;                                     // images dropped, everything else kept
  std::array<std::optional<EncodedChunk>, 3> chunks;  // colour, depth, ir
};

class RecordingWriter {
 public:
  RecordingWriter(const std::filesystem::path& path, const RecordingHeader& header,
                  const RecordingWriterOptions& options = {});
  ~RecordingWriter();  // closes cleanly if Close() was not called
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  // Checks sizes and types against the header; throws InputError naming the
  // stream and what was expected. Thread-safe.
  EncodedFramePair Encode(FramePair frame) const;
  // Writes frames in call order; not thread-safe.
  void Append(EncodedFramePair frame);
  void Append(FramePair frame) { Append(Encode(std::move(frame))); }

  void Flush();
  void Close();

  std::int64_t frames_written() const { return frames_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  struct Impl;
  void CreateLayout();  // the recording's groups, datasets and attributes
  std::filesystem::path path_;
  std::unique_ptr<Impl> impl_;
  std::int64_t frames_ = 0;
};

}  // namespace speckle
