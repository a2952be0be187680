#pragma once
// Where frames come from: the simulator, a live camera or an importer of
// recorded data (sources/). record-session's SOURCE kinds are listed once, in
// apps/sources/source_table.cc. A source yields pairs in order; bad input is
// an InputError naming the file, raised before or while reading.
#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "recorder/frame_pair.h"
#include "recorder/recording_header.h"
#include "schemas/session_manifest.h"

namespace speckle {

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // The next pair, or nullopt at the end (or when a stop was requested).
  virtual std::optional<FramePair> Next() = 0;
  // How many pairs to expect, for progress; -1 when unknown (live capture).
  virtual std::int64_t expected_frames() const { return -1; }
};

struct PlannedRecording {
  std::string file;  // name inside the session directory, e.g. "depthboard.h5"
  RecordingHeader header;
  std::unique_ptr<FrameSource> source;
};

// Everything record-session needs to write one session.
struct SessionPlan {
  SessionManifest manifest;  // recordings are listed as they are written
  std::vector<PlannedRecording> recordings;
  // Imports are all-or-nothing (staged in a temporary directory, renamed at
  // the end); streaming sources write in place so a kill keeps what was flushed.
  bool streaming = false;
  std::vector<std::string> notes;  // things the user should know (skipped frames, ...)
};

// Set by SIGINT/SIGTERM during recording: sources end their stream cleanly.
std::atomic<bool>& StopRequested();

}  // namespace speckle
