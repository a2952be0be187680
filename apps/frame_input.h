#pragma once
// The frames apply-calibration and measure read: every recording of a
// session directory (or one of them), or a libfreenect `record` dump given
// as fakenect:DIR. Sizes and units are checked against a calibration before
// any frame is read.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apply/depth_calibration.h"
#include "recorder/frame_source.h"

namespace speckle {

struct InputRecording {
  std::string name;            // "depthboard", "planar", ... or "fakenect"
  std::filesystem::path path;  // the recording file or dump folder, for messages
  RecordingHeader header;
  std::unique_ptr<FrameSource> frames;
  std::int64_t frame_count = 0;
};

struct FrameInput {
  std::optional<std::filesystem::path> session_dir;  // when the input is a session
  // A session's first host time, from which its time effects count
  // (recorder/recording_clock.h); -1: each recording counts from its own.
  std::int64_t clock_origin_ns = -1;
  std::vector<InputRecording> recordings;
};

// `input`: SESSION_DIR or fakenect:DIR; `only`: a recording's name or file
// (e.g. "planar" or "planar.h5"), empty for all with a depth stream.
// Throws InputError naming the directory or file.
FrameInput OpenFrameInput(const std::string& input, const std::string& only);

// The calibration to apply: `flag` when given, else the session's newest
// version. Throws InputError when there is neither.
std::filesystem::path ChooseCalibration(const std::string& flag, const FrameInput& input);

// Throws InputError naming the recording when its depth frames do not have
// the calibration's size or units, or (with `colour`) its colour frames the
// colour camera's size.
void CheckMatchesCalibration(const InputRecording& recording, const apply::DepthCalibration& calibration, bool colour);

}  // namespace speckle
