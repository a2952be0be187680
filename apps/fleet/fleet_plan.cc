#include "apps/fleet/fleet_plan.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <map>

#include "schemas/artifact_schema.h"
#include "schemas/errors.h"
#include "schemas/json_fields.h"
#include "schemas/session_manifest.h"

namespace speckle::fleet {
namespace fs = std::filesystem;
namespace {

constexpr const char* kPlanSchema = "speckle.fleet_plan";

std::string SerialOf(const fs::path& session) {
  const std::string serial = ReadSessionManifest(session).sensor.serial;
  return serial.empty() ? session.filename().string() : serial;
}

std::vector<Unit> FromFolder(const fs::path& folder) {
  if (fs::exists(folder / kSessionFileName))
    throw InputError(folder.string() + ": a session, not a fleet; give the folder that holds the sessions");
  std::vector<fs::path> sessions;
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.is_directory() && fs::exists(entry.path() / kSessionFileName)) sessions.push_back(entry.path());
  std::sort(sessions.begin(), sessions.end());
  std::vector<Unit> units;
  for (const auto& s : sessions) units.push_back({SerialOf(s), fs::absolute(s), {}});
  return units;
}

void RequireSession(const fs::path& file, int number, const fs::path& session, const char* what) {
  if (!fs::exists(session / kSessionFileName))
    throw InputError(fmt::format("{}: line {}: {} is not {} (no {})", file.string(), number, session.string(), what,
                                 kSessionFileName));
}

// UTF-8 without control bytes (tabs and a Windows line end allowed).
bool IsText(const std::string& line) {
  for (std::size_t i = 0; i < line.size();) {
    const auto c = static_cast<unsigned char>(line[i]);
    const int follow = c < 0x80 ? 0 : (c >> 5) == 6 ? 1 : (c >> 4) == 14 ? 2 : (c >> 3) == 30 ? 3 : -1;
    if (follow < 0 || (c < 0x20 && c != '\t' && c != '\r') || c == 0x7f || (follow > 0 && i + follow >= line.size()))
      return false;
    for (int k = 1; k <= follow; ++k)
      if ((static_cast<unsigned char>(line[i + k]) >> 6) != 2) return false;
    i += 1 + follow;
  }
  return true;
}

std::vector<Unit> FromList(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": cannot be read");
  std::vector<Unit> units;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    // A binary file's bytes went to the terminal raw, cut at the first NUL
    // (issue 47's outside probe).
    if (!IsText(line))
      throw InputError(
          fmt::format("{}: line {}: holds bytes that are not text: not a fleet list (lines "
                      "\"serial,session[,check_recording]\")",
                      file.string(), number));
    line = line.substr(0, line.find('#'));
    const std::size_t comma = line.find(',');
    const auto trim = [](std::string t) {
      t.erase(0, t.find_first_not_of(" \t\r"));
      t.erase(t.find_last_not_of(" \t\r") + 1);
      return t;
    };
    if (trim(line).empty() || trim(line) == "serial,session" || trim(line) == "serial,session,check_recording")
      continue;
    if (comma == std::string::npos)
      throw InputError(fmt::format("{}: line {}: expected \"serial,session[,check_recording]\", found \"{}\"",
                                   file.string(), number, trim(line)));
    std::string rest = line.substr(comma + 1);
    const std::size_t second = rest.find(',');
    const std::string check = second == std::string::npos ? "" : trim(rest.substr(second + 1));
    rest = rest.substr(0, second);
    const std::string serial = trim(line.substr(0, comma));
    const fs::path session = fs::absolute(file.parent_path() / trim(rest));
    if (serial.empty()) throw InputError(fmt::format("{}: line {}: no serial", file.string(), number));
    RequireSession(file, number, session, "a session");
    const fs::path recording = check.empty() ? fs::path() : fs::absolute(file.parent_path() / check);
    if (!check.empty()) RequireSession(file, number, recording, "a check recording");
    if (!check.empty() && fs::equivalent(recording, session))
      throw InputError(
          fmt::format("{}: line {}: the check recording is the unit's own session; a check needs a "
                      "second recording of the unit",
                      file.string(), number));
    units.push_back({serial, session, recording});
  }
  return units;
}

}  // namespace

std::vector<Unit> ReadManifest(const fs::path& manifest) {
  if (!fs::exists(manifest)) throw InputError(manifest.string() + ": no such fleet manifest (a folder or a list)");
  std::vector<Unit> units = fs::is_directory(manifest) ? FromFolder(manifest) : FromList(manifest);
  if (units.empty())
    throw InputError(manifest.string() + ": no sessions in it (a folder of sessions, or \"serial,session\" lines)");
  std::map<std::string, fs::path> seen;
  for (const auto& u : units) {
    // The serial names the unit's files in the fleet folder: no path in it.
    if (u.serial.starts_with('.') ||
        u.serial.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789._-") !=
            std::string::npos)
      throw InputError(fmt::format("{}: serial \"{}\" of {}: use letters, digits, '.', '_' and '-' (not first '.')",
                                   manifest.string(), u.serial, u.session.string()));
    const auto [it, fresh] = seen.emplace(u.serial, u.session);
    if (!fresh)
      throw InputError(fmt::format("{}: serial {} is given twice ({} and {})", manifest.string(), u.serial,
                                   it->second.string(), u.session.string()));
  }
  return units;
}

nlohmann::json ToJson(const Plan& plan) {
  nlohmann::json units = nlohmann::json::array();
  for (const auto& u : plan.units)
    units.push_back(
        {{"serial", u.serial}, {"session", u.session.string()}, {"check_recording", u.check_recording.string()}});
  return {{"schema", kPlanSchema},
          {"schema_version", kPlanSchemaVersion},
          {"units", units},
          {"run_pipeline", plan.run_pipeline},
          {"check", plan.check},
          {"pipeline_args", plan.pipeline_args},
          {"threads_per_unit", plan.threads_per_unit}};
}

Plan ReadPlan(const fs::path& file) {
  const nlohmann::json j = ReadArtifactJson(file, kPlanSchema, kPlanSchemaVersion);
  Plan plan;
  try {
    for (const auto& u : j.at("units"))
      plan.units.push_back({u.at("serial"), fs::path(u.at("session").get<std::string>()),
                            fs::path(u.at("check_recording").get<std::string>())});
    plan.run_pipeline = j.at("run_pipeline");
    plan.check = j.at("check");
    plan.pipeline_args = j.at("pipeline_args").get<std::vector<std::string>>();
    plan.threads_per_unit = j.at("threads_per_unit");
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file.string() + ": " + e.what());
  }
  return plan;
}

fs::path PlanFile(const fs::path& fleet) { return fleet / "fleet_plan.json"; }
fs::path UnitRecordFile(const fs::path& fleet, const Unit& unit) { return fleet / "units" / (unit.serial + ".json"); }
fs::path UnitLogFile(const fs::path& fleet, const Unit& unit) { return fleet / "logs" / (unit.serial + ".log"); }
fs::path UnitCheckLogFile(const fs::path& fleet, const Unit& unit) {
  return fleet / "logs" / (unit.serial + ".check.log");
}

}  // namespace speckle::fleet
