#include "apps/fleet/fleet_unit.h"

#include <fmt/format.h>

#include <chrono>
#include <fstream>
#include <map>

#include "apps/depth_sigmas.h"
#include "apps/fleet/child_process.h"
#include "schemas/artifact_schema.h"
#include "schemas/atomic_file.h"
#include "schemas/errors.h"
#include "schemas/json_fields.h"

namespace speckle::fleet {
namespace fs = std::filesystem;
namespace {

constexpr const char* kUnitSchema = "speckle.fleet_unit";

std::string LastErrorLine(const fs::path& log) {
  std::ifstream in(log);
  std::string last, error;
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    last = line;
    if (line.find("error") != std::string::npos) error = line;
  }
  return error.empty() ? last : error;
}

fs::path NewestVersion(const fs::path& session) {
  fs::path newest;
  if (fs::is_directory(session / "calibrations"))
    for (const auto& e : fs::directory_iterator(session / "calibrations"))
      if (e.is_directory() && e.path().filename().string().starts_with("v") && e.path() > newest) newest = e.path();
  return newest;
}

double Number(const nlohmann::json& j) { return j.is_number() ? j.get<double>() : 0.0; }

// The depth model's parameters (but large grids: a pattern or a field has
// hundreds, judged by their own plots), the depth camera and the extrinsics.
std::vector<Parameter> ParametersOf(const nlohmann::json& calibration) {
  std::vector<Parameter> out;
  std::map<std::string, int> per_block;
  for (const auto& p : calibration["model"]["parameters"]) ++per_block[p.value("block", "")];
  for (const auto& p : calibration["model"]["parameters"])
    if (per_block[p.value("block", "")] <= 6)
      out.push_back(
          {"model." + (p.value("block", "") == "base" ? "" : p.value("block", "") + ".") + p.value("name", ""),
           Number(p["value"]), Number(p["sigma"])});
  const auto& depth = calibration["cameras"]["depth"];
  const auto sigma = depth.value("stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3", std::vector<double>(4, 0.0));
  const char* names[] = {"fx", "fy", "cx", "cy"};
  for (int i = 0; i < 4; ++i)
    out.push_back({std::string("depth.") + names[i], Number(depth[names[i]]), i < int(sigma.size()) ? sigma[i] : 0});
  const auto& extrinsics = calibration["cameras"]["depth_from_colour"];
  for (int i = 0; i < 3; ++i)
    out.push_back({fmt::format("depth_from_colour.t{}", "xyz"[i]), Number(extrinsics["translation_m"][i]),
                   Number(extrinsics["translation_sigma_m"][i])});
  return out;
}

void ReadVersion(const fs::path& version, UnitRecord& r) {
  const nlohmann::json calibration = ReadJsonFile((version / "calibration.json").string());
  const nlohmann::json report = ReadJsonFile((version / "report.json").string());
  r.version = version.string();
  r.model = calibration["model"].value("name", "");
  r.conclusion = report["diagnosis"].value("conclusion", "");
  r.held_out_to_floor = Number(report["diagnosis"]["ratio_to_floor"]);
  const apply::DepthSigmaTable sigmas = DepthSigmasOf(version / "calibration.json");
  r.depth_sigma_mm_at_1m = sigmas.depth_m.empty() ? 0 : 1e3 * sigmas.At(1.0);
  for (const auto& p : calibration["plausibility"].value("problems", nlohmann::json::array()))
    r.plausibility_problems.push_back(p.is_string() ? p.get<std::string>() : p.dump());
  r.parameters = ParametersOf(calibration);
}

// check's exit codes (apps/check_main.cc) as the summary says them.
std::string CheckStatus(int exit_code) {
  switch (exit_code) {
    case 0:
      return "OK";
    case 10:
      return "DEGRADED";
    case 11:
      return "RECALIBRATE";
    case 12:
      return "CANNOT JUDGE";
    default:
      return fmt::format("check failed: exit {}", exit_code);
  }
}

// The end-of-line test: the calibration just made, scored on a second
// recording of the unit, into a new folder named by the version (a unit run
// again may name the version it made before). A check that cannot run is
// the check's failure, not the calibration's.
void CheckUnit(const fs::path& fleet, const Plan& plan, const Unit& unit, UnitRecord& r) {
  if (unit.check_recording.empty()) return;
  try {
    const fs::path stem =
        fs::absolute(fleet) / "checks" / (unit.serial + "-" + fs::path(r.version).filename().string());
    fs::path out = stem;
    for (int n = 2; fs::exists(out); ++n) out = stem.string() + "-" + std::to_string(n);
    fs::create_directories(out.parent_path());
    r.check_folder = out.string();
    r.check_status = CheckStatus(RunLogged({plan.check, r.version, unit.check_recording.string(), "--out", out.string(),
                                            "--threads", std::to_string(plan.threads_per_unit)},
                                           UnitCheckLogFile(fleet, unit)));
  } catch (const std::exception& e) {
    r.check_status = std::string("check failed: ") + e.what();
  }
}

}  // namespace

bool CheckPassedOrNotAsked(const UnitRecord& r) { return r.check_status == "OK" || r.check_status == "not checked"; }

bool CheckFailed(const UnitRecord& r) { return r.check_status.starts_with("check failed"); }

UnitRecord RunUnit(const fs::path& fleet, const Plan& plan, std::size_t index) {
  const Unit& unit = plan.units.at(index);
  UnitRecord r{.serial = unit.serial, .session = unit.session.string()};
  fs::create_directories(fleet / "logs");
  fs::create_directories(fleet / "units");
  std::vector<std::string> argv{plan.run_pipeline, unit.session.string(), "--threads",
                                std::to_string(plan.threads_per_unit)};
  argv.insert(argv.end(), plan.pipeline_args.begin(), plan.pipeline_args.end());
  const auto start = std::chrono::steady_clock::now();
  try {
    r.exit_code = RunLogged(argv, UnitLogFile(fleet, unit));
    if (r.exit_code == 0) ReadVersion(NewestVersion(unit.session), r);
    r.calibrated = r.exit_code == 0;
    if (!r.calibrated) r.reason = LastErrorLine(UnitLogFile(fleet, unit));
    if (r.calibrated) CheckUnit(fleet, plan, unit, r);
  } catch (const std::exception& e) {
    r.calibrated = false;
    r.reason = e.what();
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  WriteFileAtomically(UnitRecordFile(fleet, unit), ToJson(r).dump(1) + "\n");
  return r;
}

nlohmann::json ToJson(const UnitRecord& r) {
  nlohmann::json parameters = nlohmann::json::array();
  for (const auto& p : r.parameters) parameters.push_back({{"name", p.name}, {"value", p.value}, {"sigma", p.sigma}});
  return {{"schema", kUnitSchema},
          {"schema_version", kUnitSchemaVersion},
          {"serial", r.serial},
          {"session", r.session},
          {"calibrated", r.calibrated},
          {"exit_code", r.exit_code},
          {"reason", r.reason},
          {"version", r.version},
          {"model", r.model},
          {"conclusion", r.conclusion},
          {"held_out_to_floor", r.held_out_to_floor},
          {"depth_sigma_mm_at_1m", r.depth_sigma_mm_at_1m},
          {"plausibility_problems", r.plausibility_problems},
          {"parameters", parameters},
          {"check_status", r.check_status},
          {"check_folder", r.check_folder},
          {"seconds", r.seconds}};
}

std::optional<UnitRecord> ReadUnitRecord(const fs::path& fleet, const Unit& unit) {
  const fs::path file = UnitRecordFile(fleet, unit);
  if (!fs::exists(file)) return std::nullopt;
  const nlohmann::json j = ReadArtifactJson(file, kUnitSchema, kUnitSchemaVersion);
  try {
    UnitRecord r{.serial = j.at("serial"),
                 .session = j.at("session"),
                 .calibrated = j.at("calibrated"),
                 .exit_code = j.at("exit_code"),
                 .reason = j.at("reason"),
                 .version = j.at("version"),
                 .model = j.at("model"),
                 .conclusion = j.at("conclusion"),
                 .held_out_to_floor = j.at("held_out_to_floor"),
                 .depth_sigma_mm_at_1m = j.at("depth_sigma_mm_at_1m"),
                 .plausibility_problems = j.at("plausibility_problems"),
                 .check_status = j.at("check_status"),
                 .check_folder = j.at("check_folder"),
                 .seconds = j.at("seconds")};
    for (const auto& p : j.at("parameters")) r.parameters.push_back({p.at("name"), p.at("value"), p.at("sigma")});
    return r;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file.string() + ": " + e.what());
  }
}

}  // namespace speckle::fleet
