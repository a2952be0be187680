#include "schemas/staging.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <fstream>
#include <random>
#include <regex>
#include <stdexcept>

#include <spdlog/spdlog.h>

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

std::string MarkerText(std::int64_t pid) { return "speckle staging folder of process " + std::to_string(pid) + "\n"; }

// A folder whose marker names `pid`, or a regular file that starts as HDF5
// files do (the only files the tools stage) or is still empty (a recorder
// killed before HDF5 wrote its first bytes; removing it loses nothing):
// never a link, never anything else.
bool IsOurLeftover(const fs::path& path, std::int64_t pid) {
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(path, ec);
  if (ec) return false;
  const bool folder = fs::is_directory(status);
  if (!folder && !fs::is_regular_file(status)) return false;
  if (!folder && fs::file_size(path, ec) == 0 && !ec) return true;
  const fs::path marker = folder ? path / kStagingMarker : path;
  if (!fs::is_regular_file(fs::symlink_status(marker, ec))) return false;
  const std::string expected = folder ? MarkerText(pid) : std::string("\x89HDF\r\n\x1a\n", 8);
  std::ifstream in(marker, std::ios::binary);
  std::string head(expected.size() + (folder ? 1 : 0), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head == expected;
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

void CreateStagingFolder(const fs::path& staging) {
  if (!fs::create_directory(staging)) throw std::runtime_error(staging.string() + ": exists already");
  std::ofstream marker(staging / kStagingMarker, std::ios::binary);
  marker << MarkerText(::getpid());
  if (!marker.flush()) throw std::runtime_error((staging / kStagingMarker).string() + ": cannot write");
}

void RemoveStagingMarker(const fs::path& staging) { fs::remove(staging / kStagingMarker); }

void RemoveStaleStaging(const fs::path& dir) {
  // Exactly the names Suffix() makes: a PID from 1 and a number of up to 6 digits.
  static const std::regex kStaging(R"(^(?:\..+\.partial|\.incoming)-([1-9]\d{0,9})-\d{1,6}$)");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    std::smatch m;
    if (!std::regex_match(name, m, kStaging)) continue;
    const auto pid = ParseDecimal(m[1].str());
    if (!pid || Running(*pid) || !IsOurLeftover(entry.path(), *pid)) continue;
    spdlog::warn("removing {}, a leftover of process {} (no longer running)", entry.path().string(), m[1].str());
    std::error_code removed;
    fs::remove_all(entry.path(), removed);
    if (removed) spdlog::warn("{}: could not be removed: {}", entry.path().string(), removed.message());
  }
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
