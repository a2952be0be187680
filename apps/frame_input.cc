#include "apps/frame_input.h"

#include <fmt/format.h>

#include "apps/depth_sigmas.h"
#include "model/depth_model.h"
#include "recorder/manifest_agreement.h"
#include "recorder/recording_clock.h"
#include "recorder/recording_reader.h"
#include "recorder/sources/fakenect_source.h"
#include "schemas/calibration_versions.h"
#include "schemas/errors.h"
#include "schemas/session_manifest.h"

namespace speckle {
namespace {

namespace fs = std::filesystem;

class RecordingFrames : public FrameSource {
 public:
  explicit RecordingFrames(std::shared_ptr<RecordingReader> reader) : reader_(std::move(reader)) {}
  std::int64_t expected_frames() const override { return reader_->frame_count(); }
  std::optional<FramePair> Next() override {
    if (next_ >= reader_->frame_count()) return std::nullopt;
    return reader_->ReadFrame(next_++);
  }

 private:
  std::shared_ptr<RecordingReader> reader_;
  std::int64_t next_ = 0;
};

std::string SizeText(const cv::Size& s) { return fmt::format("{} x {}", s.width, s.height); }

}  // namespace

FrameInput OpenFrameInput(const std::string& input, const std::string& only) {
  FrameInput result;
  if (input.rfind("fakenect:", 0) == 0) {
    FakenectImportOptions options;
    options.allow_unpaired = true;  // depth alone is enough to apply a calibration
    std::vector<std::string> notes;
    PlannedRecording plan = PlanFakenectImport(input.substr(9), options, &notes);
    const std::int64_t count = plan.source->expected_frames();
    result.recordings.push_back({"fakenect", input.substr(9), plan.header, std::move(plan.source), count});
    return result;
  }
  const fs::path session = input;
  if (!fs::is_directory(session))
    throw InputError(input + ": not a directory (expected a session directory or fakenect:DUMP_DIR)");
  result.session_dir = session;
  const SessionManifest manifest = ReadSessionManifest(session);
  std::vector<std::shared_ptr<RecordingReader>> readers;
  for (const RecordingEntry& entry : manifest.recordings) {
    readers.push_back(std::make_shared<RecordingReader>(session / entry.file));
    RefuseManifestDisagreements(session, entry, readers.back()->header(), manifest);
  }
  // Every recording's clock, not only the one asked for: the walls recorded
  // after the boards are that far into the sensor's warm-up.
  std::vector<const RecordingReader*> all;
  for (const auto& r : readers) all.push_back(r.get());
  result.clock_origin_ns = FirstHostTimeNs(all);
  for (std::size_t k = 0; k < manifest.recordings.size(); ++k) {
    const RecordingEntry& entry = manifest.recordings[k];
    const std::string name = fs::path(entry.file).stem().string();
    if (!only.empty() && only != name && only != entry.file) continue;
    const std::shared_ptr<RecordingReader>& reader = readers[k];
    if (!reader->header().depth_size) continue;
    const std::int64_t count = reader->frame_count();
    const RecordingHeader header = reader->header();
    result.recordings.push_back({name, session / entry.file, header, std::make_unique<RecordingFrames>(reader), count});
  }
  if (result.recordings.empty()) {
    throw InputError(only.empty() ? input + ": the session has no recording with a depth stream"
                                  : input + ": no recording \"" + only + "\" with a depth stream in session.json");
  }
  return result;
}

fs::path ChooseCalibration(const std::string& flag, const FrameInput& input) {
  // A session, a version folder or a calibration.json, as check and compare
  // take it (a session was "S/calibration.json: missing").
  if (!flag.empty()) return CalibrationFile(flag);
  if (!input.session_dir) throw InputError("--calibration is needed: a fakenect dump holds no calibration");
  return NewestCalibrationVersion(*input.session_dir, "run run-pipeline first, or pass --calibration");
}

void CheckMatchesCalibration(const InputRecording& r, const apply::DepthCalibration& c, bool colour) {
  const cv::Size depth(c.depth.width, c.depth.height);
  if (*r.header.depth_size != depth) {
    throw InputError(fmt::format("{}: depth frames are {}, expected {} as the depth camera of {}", r.path.string(),
                                 SizeText(*r.header.depth_size), SizeText(depth), c.file.string()));
  }
  if (r.header.depth_units != c.depth_units) {
    throw InputError(fmt::format("{}: depth frames hold {}, expected {} for the {} model of {}", r.path.string(),
                                 ToString(r.header.depth_units), ToString(c.depth_units),
                                 model::Info(c.model->Definition().form).name, c.file.string()));
  }
  const cv::Size rgb(c.colour.width, c.colour.height);
  if (colour && r.header.colour_size && *r.header.colour_size != rgb) {
    throw InputError(
        fmt::format("{}: colour frames are {}, expected {} as the colour camera of {} (or pass --no-colour)",
                    r.path.string(), SizeText(*r.header.colour_size), SizeText(rgb), c.file.string()));
  }
}

}  // namespace speckle
