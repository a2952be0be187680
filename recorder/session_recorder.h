#pragma once
// Writes a SessionPlan to a new session directory.
#include <filesystem>
#include <string>
#include <vector>

#include "recorder/frame_source.h"
#include "recorder/recording_writer.h"

namespace speckle {

struct SessionRecorderOptions {
  RecordingWriterOptions writer;
  // Frames in flight between reading and writing (bounds memory; ~1.5 MB each).
  int frames_in_flight = 8;
};

struct RecordedFile {
  std::string file;
  RecordingPurpose purpose = RecordingPurpose::kFree;
  std::int64_t frames = 0;
};

struct SessionRecordSummary {
  std::filesystem::path session_dir;
  std::vector<RecordedFile> recordings;
  bool stopped_early = false;  // a stop was requested (Ctrl-C)
};

// Writes every frame of `source` through `writer` (serial read, parallel
// compression, in-order write) and closes it; returns the frames written.
std::int64_t WriteRecording(FrameSource& source, RecordingWriter& writer, const std::string& stage,
                            int frames_in_flight);

// The session.json entry for a planned recording, naming where it came from.
RecordingEntry EntryFor(const PlannedRecording& planned);

// Refuses an existing `session_dir`. Imports (plan.streaming == false) are
// staged in a hidden sibling directory and renamed on success, so a failure
// leaves nothing behind; streaming sources record in place.
SessionRecordSummary RecordSession(SessionPlan plan, const std::filesystem::path& session_dir,
                                   const SessionRecorderOptions& options = {});

}  // namespace speckle
