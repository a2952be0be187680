#pragma once
// What `session-info` reports: the manifest, each recording's contents, and
// every problem found while validating them against the format.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "recorder/recording_reader.h"
#include "schemas/session_manifest.h"

namespace speckle {

struct RecordingSummary {
  std::string file;
  RecordingPurpose purpose = RecordingPurpose::kFree;
  std::string source;
  std::string source_path;  // the dump or folder it was imported from
  std::int64_t frames = 0;
  std::int64_t colour_frames = 0, depth_frames = 0, ir_frames = 0;  // valid ones
  std::string colour_size, depth_size, ir_size;                     // "WxH" or ""
  std::string depth_units;
  double time_span_s = 0;
  std::int64_t accel_samples = 0;
  bool has_truth = false;
  bool has_device_registration = false;
  bool closed_cleanly = true;
  std::string note;
  std::string unreadable;  // why it could not be read at all ("" when it could)
};

struct SessionSummary {
  SessionManifest manifest;
  std::vector<RecordingSummary> recordings;
  std::vector<std::string> problems;  // empty = valid
};

// Throws InputError when session.json itself is unreadable; problems with
// individual recordings are collected in `problems`.
SessionSummary InspectSession(const std::filesystem::path& session_dir);

// The span of a recording's host times, seconds (0 without any).
double HostTimeSpanS(const RecordingReader& reader);
// Host times no recording can hold (issue 47: session-info said "valid: yes"
// for them): before 1970, or one recording spanning more than a day, where a
// Kinect session lasts minutes. The thermal covariates read these times, so
// run-pipeline refuses them too. "" when there are none; else the problem,
// naming `file` and the frame.
std::string ImpossibleTimes(const RecordingReader& reader, const std::string& file);
nlohmann::json ToJson(const SessionSummary& summary);
std::string FormatSummary(const SessionSummary& summary);

}  // namespace speckle
