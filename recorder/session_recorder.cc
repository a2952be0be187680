#include "recorder/session_recorder.h"

#include <spdlog/spdlog.h>
#include <tbb/parallel_pipeline.h>

#include <random>

#include "recorder/progress.h"
#include "recorder/stop_signal.h"
#include "schemas/atomic_file.h"
#include "schemas/atomic_folder.h"
#include "schemas/errors.h"
#include "schemas/staging.h"
#include "speckle/tool_version.h"

namespace speckle {

std::atomic<bool>& StopRequested() {
  static std::atomic<bool> stop{false};
  return stop;
}

RecordingEntry EntryFor(const PlannedRecording& planned) {
  return {planned.file, planned.header.purpose, planned.header.source, planned.header.source_path};
}

std::int64_t WriteRecording(FrameSource& source, RecordingWriter& writer, const std::string& stage, int in_flight) {
  Progress progress(stage, source.expected_frames());
  tbb::parallel_pipeline(
      static_cast<std::size_t>(in_flight),
      tbb::make_filter<void, std::shared_ptr<FramePair>>(tbb::filter_mode::serial_in_order,
                                                         [&](tbb::flow_control& control) -> std::shared_ptr<FramePair> {
                                                           auto frame = source.Next();
                                                           if (!frame) {
                                                             control.stop();
                                                             return nullptr;
                                                           }
                                                           return std::make_shared<FramePair>(std::move(*frame));
                                                         }) &
          tbb::make_filter<std::shared_ptr<FramePair>, std::shared_ptr<EncodedFramePair>>(
              tbb::filter_mode::parallel,
              [&](std::shared_ptr<FramePair> frame) {
                return std::make_shared<EncodedFramePair>(writer.Encode(std::move(*frame)));
              }) &
          tbb::make_filter<std::shared_ptr<EncodedFramePair>, void>(tbb::filter_mode::serial_in_order,
                                                                    [&](std::shared_ptr<EncodedFramePair> frame) {
                                                                      writer.Append(std::move(*frame));
                                                                      progress.Update(writer.frames_written());
                                                                    }));
  progress.Finish();
  writer.Close();
  return writer.frames_written();
}

SessionRecordSummary RecordSession(SessionPlan plan, const std::filesystem::path& session_dir,
                                   const SessionRecorderOptions& options) {
  namespace fs = std::filesystem;
  if (fs::exists(session_dir)) {
    throw InputError(session_dir.string() + ": already exists; choose a new session directory");
  }
  const fs::path parent = fs::absolute(session_dir).parent_path();
  fs::create_directories(parent);
  RemoveStaleStaging(parent);
  SessionManifest manifest = plan.manifest;
  manifest.created_utc = UtcNowIso8601();
  manifest.tool_version = kToolVersion;
  manifest.recordings.clear();
  SessionRecordSummary summary{session_dir, {}, false};
  StopSignalScope stop_scope;
  const auto record = [&](const fs::path& work_dir) {
    WriteSessionManifest(work_dir, manifest);
    for (PlannedRecording& planned : plan.recordings) {
      if (StopRequested()) break;
      RecordingWriter writer(work_dir / planned.file, planned.header, options.writer);
      // List the file before its first frame: a killed recorder's session
      // still names every recording it started.
      manifest.recordings.push_back(EntryFor(planned));
      WriteSessionManifest(work_dir, manifest);
      const std::int64_t frames =
          WriteRecording(*planned.source, writer, ToString(planned.header.purpose), options.frames_in_flight);
      summary.recordings.push_back({planned.file, planned.header.purpose, frames});
    }
    summary.stopped_early = StopRequested();
  };
  if (plan.streaming) {  // a live device: what was flushed stays, even if the recorder is killed
    fs::create_directory(session_dir);
    record(session_dir);
    return summary;
  }
  WriteFolderAside(
      PartialPathFor(fs::absolute(session_dir)),
      [&](const fs::path& work_dir) {
        record(work_dir);
        if (summary.stopped_early) throw InputError("import interrupted; nothing was written");
      },
      [&](const fs::path& work_dir) { return RenameInto(work_dir, session_dir); });
  return summary;
}

}  // namespace speckle
