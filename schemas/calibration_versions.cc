#include "schemas/calibration_versions.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <regex>

#include "schemas/atomic_file.h"
#include "schemas/decimal_text.h"
#include "schemas/errors.h"
#include "schemas/json_fields.h"
#include "schemas/staging.h"

namespace speckle {
namespace fs = std::filesystem;

std::vector<fs::path> CalibrationVersions(const fs::path& session_dir) {
  static const std::regex kVersion(R"(v(\d{4,}))");
  std::vector<std::pair<std::int64_t, fs::path>> numbered;
  const fs::path root = session_dir / "calibrations";
  RefuseSymlinkInside(session_dir, root);
  if (fs::exists(root)) {
    for (const auto& entry : fs::directory_iterator(root)) {
      std::smatch m;
      const std::string name = entry.path().filename().string();
      if (!std::regex_match(name, m, kVersion)) continue;
      // A hand-made v99999999999 is not one of ours: named, then left alone.
      const auto number = ParseDecimal(m[1].str(), kMaxCalibrationVersion);
      if (!number) {
        spdlog::warn("{}: ignored: version numbers run from 1 to {}", entry.path().string(), kMaxCalibrationVersion);
        continue;
      }
      numbered.emplace_back(*number, entry.path());
    }
  }
  std::sort(numbered.begin(), numbered.end());
  std::vector<fs::path> versions;
  for (auto& [number, path] : numbered) versions.push_back(std::move(path));
  return versions;
}

namespace {

// Whether its writer flagged the version (apply/plausibility.h); an
// unreadable calibration.json is for the reader to name, so not flagged here.
bool FlaggedImplausible(const fs::path& version) {
  try {
    const nlohmann::json j = ReadJsonFile((version / "calibration.json").string());
    const nlohmann::json& p = j.value("plausibility", nlohmann::json::object());
    return p.is_object() && p.value("problems", nlohmann::json::array()).size() > 0 && !p.value("accepted", false);
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

fs::path NewestCalibrationVersion(const fs::path& session_dir, const std::string& hint) {
  const std::vector<fs::path> versions = CalibrationVersions(session_dir);
  if (versions.empty()) throw InputError(session_dir.string() + ": no calibration (" + hint + ")");
  for (auto v = versions.rbegin(); v != versions.rend(); ++v) {
    if (!FlaggedImplausible(*v)) return *v;
    spdlog::warn(
        "{}: passed by: its writer found it no calibration a Kinect v1 / PrimeSense sensor gives "
        "(calibration.json \"plausibility\")",
        v->string());
  }
  // Every version passed by: say so, not load the newest to refuse it on a
  // field (issue 47's probe found that contradictory).
  throw InputError(session_dir.string() + ": no usable calibration: every version (" +
                   versions.front().filename().string() +
                   (versions.size() > 1 ? " to " + versions.back().filename().string() : std::string()) +
                   ") was flagged by its writer as no calibration a Kinect v1 / PrimeSense sensor gives; its "
                   "calibration.json's \"plausibility\" says what is wrong and the likely cause; mend that and run "
                   "run-pipeline again");
}

fs::path PublishCalibrationVersion(const fs::path& session_dir, const fs::path& staging) {
  const fs::path root = session_dir / "calibrations";
  const std::vector<fs::path> existing = CalibrationVersions(session_dir);
  std::int64_t next =
      existing.empty() ? 1 : ParseDecimal(existing.back().filename().string().substr(1)).value_or(0) + 1;
  for (int attempt = 0; attempt < 100; ++attempt, ++next) {
    if (next > kMaxCalibrationVersion)
      throw InputError(root.string() + ": no version number left (the last is v" + std::to_string(next - 1) +
                       "; at most " + std::to_string(kMaxCalibrationVersion) + ")");
    char name[24];
    std::snprintf(name, sizeof name, "v%04lld", static_cast<long long>(next));
    const fs::path target = root / name;
    if (fs::exists(target)) continue;
    std::error_code ec;
    fs::rename(staging, target, ec);
    if (!ec) {
      SyncPath(root);
      return target;
    }
  }
  throw std::runtime_error("could not claim a version directory under " + root.string());
}

}  // namespace speckle
