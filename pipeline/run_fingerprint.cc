#include "pipeline/run_fingerprint.h"

#include <fmt/format.h>

#include <iostream>

#include "pipeline/plausibility_gate.h"

#include "pipeline/sha256_file.h"
#include "schemas/calibration_versions.h"
#include "schemas/json_fields.h"

namespace speckle {

namespace fs = std::filesystem;

std::string RunFingerprint(nlohmann::json what) {
  // Hashed once a process: the executable does not change under a run.
  static const std::string build = Sha256File("/proc/self/exe");
  what["build_sha256"] = build;
  return Sha256Text(what.dump());
}

std::optional<fs::path> VersionWithFingerprint(const fs::path& session_dir, const std::string& fingerprint) {
  const std::vector<fs::path> versions = CalibrationVersions(session_dir);
  for (auto v = versions.rbegin(); v != versions.rend(); ++v) {
    try {
      const nlohmann::json c = ReadJsonFile(*v / "calibration.json");
      if (c.value("run_fingerprint", std::string()) == fingerprint) return *v;
    } catch (const std::exception&) {
      // An unreadable version is no match; the run goes on and writes its own.
    }
  }
  return std::nullopt;
}

void SayUnchanged(const fs::path& version) {
  const nlohmann::json c = ReadJsonFile(version / "calibration.json");
  const auto number = [&](const char* pointer) -> std::string {
    const nlohmann::json v = c.value(nlohmann::json::json_pointer(pointer), nlohmann::json());
    return v.is_number() ? fmt::format("{:.3f}", v.get<double>()) : std::string("?");
  };
  std::cout << fmt::format(
      "calibration  {}\n"
      "unchanged    {} made it from the same inputs, model and options with this same build: no new version "
      "written (--new-version writes one anyway)\n"
      "model        {}: held out {} raw ({} mm), {} x the floor; the summary is in its report.json\n",
      version.string(), version.filename().string(), c.value("/model/name"_json_pointer, std::string("?")),
      number("/metrics/held_out_raw/rms"), number("/metrics/held_out_mm/rms"), number("/metrics/held_out_to_floor"));
  EndIfImplausible(version, c.at("plausibility"));
}

}  // namespace speckle
