#include "recorder/session_append.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>

#include <spdlog/spdlog.h>

#include "recorder/session_conflicts.h"
#include "recorder/stop_signal.h"
#include "schemas/atomic_file.h"
#include "schemas/errors.h"
#include "schemas/json_fields.h"
#include "schemas/staging.h"
#include "speckle/tool_version.h"

namespace speckle {
namespace {

namespace fs = std::filesystem;

constexpr const char* kStartNewSession = "--add-to adds to an existing session; use --out to start a new one";

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open (" + std::strerror(errno) + ")");
  return {std::istreambuf_iterator<char>(in), {}};
}

// flock on the session folder itself: no lock file to leave behind, and the
// kernel drops the lock if the process dies.
class SessionLock {
 public:
  explicit SessionLock(const fs::path& session_dir) : fd_(::open(session_dir.c_str(), O_RDONLY | O_DIRECTORY)) {
    if (fd_ < 0) throw InputError(session_dir.string() + ": cannot open (" + std::strerror(errno) + ")");
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd_);
      throw InputError(session_dir.string() + ": another record-session is adding to this session; wait for it");
    }
  }
  ~SessionLock() { ::close(fd_); }
  SessionLock(const SessionLock&) = delete;
  SessionLock& operator=(const SessionLock&) = delete;

 private:
  int fd_;
};

// Files this add has made so far; removed again unless committed.
class StagedFiles {
 public:
  explicit StagedFiles(fs::path session_dir) : session_dir_(std::move(session_dir)) {}
  ~StagedFiles() {
    if (committed_) return;
    std::error_code ignored;
    for (const auto& path : made_) fs::remove(path, ignored);
    SyncPath(session_dir_);
  }
  fs::path HiddenNameFor(const std::string& file) {
    made_.push_back(PartialPathFor(session_dir_ / file));
    return made_.back();
  }
  // link(2) refuses an existing name, so a file that appeared since the
  // checks is never overwritten.
  void MoveIntoPlace(const fs::path& hidden, const std::string& file) {
    const fs::path final_path = session_dir_ / file;
    if (::link(hidden.c_str(), final_path.c_str()) != 0) {
      throw InputError(final_path.string() + ": cannot create (" + std::strerror(errno) + "); nothing was added");
    }
    made_.push_back(final_path);
    fs::remove(hidden);
  }
  void Commit() { committed_ = true; }

 private:
  fs::path session_dir_;
  std::vector<fs::path> made_;
  bool committed_ = false;
};

void ThrowIfConflicts(const fs::path& session_dir, const SessionMerge& merge) {
  if (merge.conflicts.empty()) return;
  std::string message = "cannot add to " + session_dir.string() + "; nothing was changed:";
  for (const auto& conflict : merge.conflicts) message += "\n  - " + conflict;
  throw InputError(message);
}

}  // namespace

SessionManifest ReadSessionToAppendTo(const fs::path& session_dir) {
  if (!fs::is_directory(session_dir)) {
    throw InputError(session_dir.string() + ": no such session directory (" + kStartNewSession + ")");
  }
  if (!fs::exists(session_dir / kSessionFileName)) {
    throw InputError(session_dir.string() + ": holds no " + kSessionFileName + ", so it is not a session (" +
                     kStartNewSession + ")");
  }
  return ReadSessionManifest(session_dir);
}

SessionRecordSummary AppendToSession(SessionPlan plan, const fs::path& session_dir,
                                     const SessionRecorderOptions& options) {
  ReadSessionToAppendTo(session_dir);
  const SessionLock lock(session_dir);
  RemoveStaleStaging(session_dir);
  const fs::path manifest_path = session_dir / kSessionFileName;
  const std::string manifest_bytes = ReadBytes(manifest_path);
  // Parsed from the bytes compared at the end, so what is checked is what is replaced.
  const nlohmann::json json = ParseJsonText(manifest_bytes, manifest_path.string());
  const SessionManifest session = SessionManifestFromJson(json, manifest_path.string());
  NameFurtherWalls(session, plan);
  SessionMerge merge = MergeIntoSession(session_dir, session, plan);
  ThrowIfConflicts(session_dir, merge);

  SessionRecordSummary summary{session_dir, {}, false};
  StagedFiles staged(session_dir);
  std::vector<fs::path> hidden;
  const StopSignalScope stop_scope;
  for (PlannedRecording& planned : plan.recordings) {
    hidden.push_back(staged.HiddenNameFor(planned.file));
    try {
      RecordingWriter writer(hidden.back(), planned.header, options.writer);  // Close() fsyncs it
      const std::int64_t frames =
          WriteRecording(*planned.source, writer, ToString(planned.header.purpose), options.frames_in_flight);
      summary.recordings.push_back({planned.file, planned.header.purpose, frames});
    } catch (const InputError& e) {
      throw InputError(std::string(e.what()) + "; nothing was added to " + session_dir.string());
    } catch (const fs::filesystem_error& e) {  // a full disk: named by the file it was to become
      throw InputError((session_dir / planned.file).string() + ": not added (" + std::string(FileSystemMessage(e)) +
                       "); nothing was added to " + session_dir.string());
    }
    if (StopRequested()) break;
  }
  summary.stopped_early = StopRequested();
  // A live capture ends on Ctrl-C and keeps what it recorded; an import
  // stopped half-way would add a recording missing frames.
  if (summary.stopped_early && (!plan.streaming || summary.recordings.size() < plan.recordings.size())) {
    throw InputError("interrupted; nothing was added to " + session_dir.string());
  }
  for (std::size_t i = 0; i < hidden.size(); ++i) staged.MoveIntoPlace(hidden[i], plan.recordings[i].file);
  SyncPath(session_dir);
  if (ReadBytes(manifest_path) != manifest_bytes) {
    throw InputError(manifest_path.string() + ": changed while recording; nothing was added, run the add again");
  }
  merge.manifest.tool_version = kToolVersion;
  for (const PlannedRecording& planned : plan.recordings) merge.manifest.recordings.push_back(EntryFor(planned));
  WriteSessionManifest(session_dir, merge.manifest);
  staged.Commit();
  return summary;
}

}  // namespace speckle
