#include "schemas/staging.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <random>
#include <regex>

#include "schemas/decimal_text.h"
#include "schemas/errors.h"

namespace speckle {

namespace fs = std::filesystem;

namespace {

std::string Suffix() {
  static std::random_device entropy;
  return std::to_string(::getpid()) + "-" + std::to_string(entropy() % 1000000);
}

// True unless the process is known to be gone (kill(pid, 0) fails with
// ESRCH): a process of another user still counts as running.
bool Running(std::int64_t pid) {
  if (pid <= 0 || pid > 4194304) return false;  // beyond Linux's pid_max: not a PID
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH;
}

}  // namespace

fs::path NormalizeOutPath(const std::string& value, const std::string& flag) {
  if (value.empty()) throw InputError(flag + ": expected a directory name, found an empty string");
  fs::path p = fs::path(value).lexically_normal();
  while (!p.empty() && p.filename().empty() && p.has_relative_path()) p = p.parent_path();
  const std::string name = p.filename().string();
  if (p.empty() || name.empty() || name == "." || name == "..")
    throw InputError(flag + ": \"" + value + "\" names no new directory");
  return p;
}

fs::path PartialPathFor(const fs::path& target) {
  return target.parent_path() / ("." + target.filename().string() + ".partial-" + Suffix());
}

fs::path IncomingPathIn(const fs::path& dir) { return dir / (".incoming-" + Suffix()); }

std::vector<std::string> RemoveStaleStaging(const fs::path& dir) {
  static const std::regex kStaging(R"(^(?:\..+\.partial|\.incoming)-(\d{1,12})(?:-\d+)?$)");
  std::vector<std::string> notes;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return notes;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    std::smatch m;
    if (!std::regex_match(name, m, kStaging)) continue;
    const auto pid = ParseDecimal(m[1].str());
    if (!pid || Running(*pid)) continue;
    std::error_code removed;
    fs::remove_all(entry.path(), removed);
    notes.push_back(removed ? entry.path().string() + ": leftover of process " + m[1].str() +
                                  " (no longer running) could not be removed: " + removed.message()
                            : "removed " + entry.path().string() + ", a leftover of process " + m[1].str() +
                                  " (no longer running)");
  }
  return notes;
}

void RefuseSymlinkInside(const fs::path& session_dir, const fs::path& path) {
  const fs::path relative = path.lexically_relative(session_dir);
  fs::path at = session_dir;
  for (const auto& step : relative) {
    if (step == "." || step.empty()) continue;
    if (step == "..") throw InputError(path.string() + ": outside the session " + session_dir.string());
    at /= step;
    std::error_code ec;
    if (fs::is_symlink(at, ec))
      throw InputError(at.string() + ": is a symbolic link; refusing to write outside the session through it");
  }
}

}  // namespace speckle
