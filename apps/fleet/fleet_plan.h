#pragma once
// A fleet: many sessions (one per sensor unit) calibrated in one batch. The
// plan is what every worker reads (fleet_plan.json in the fleet folder): the
// units in order, and the run-pipeline command each gets.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace speckle::fleet {

inline constexpr int kPlanSchemaVersion = 2;  // 2: a unit's check recording

struct Unit {
  std::string serial;             // the unit's name in every table
  std::filesystem::path session;  // absolute
  // A second recording of the unit (absolute), on which `check` scores the
  // new calibration: the end-of-line test. Empty: the unit is not checked.
  std::filesystem::path check_recording;
};

struct Plan {
  std::vector<Unit> units;
  std::string run_pipeline, check;         // the tools, as this fleet tool found them
  std::vector<std::string> pipeline_args;  // passed to every unit's run-pipeline
  int threads_per_unit = 1;
};

// A manifest: a folder whose sub-folders are sessions (serial: session.json's
// sensor serial, else the folder's name), or a text file of
// "serial,session[,check_recording]" lines (paths relative to the file; '#'
// starts a comment). Throws InputError naming the manifest, the line or the
// folder: a missing session or check recording, a session given as the
// fleet, a serial given twice, no units at all.
std::vector<Unit> ReadManifest(const std::filesystem::path& manifest);

nlohmann::json ToJson(const Plan& plan);
// Throws SchemaVersionError / InputError naming `file`.
Plan ReadPlan(const std::filesystem::path& file);

// Files in a fleet folder.
std::filesystem::path PlanFile(const std::filesystem::path& fleet);
std::filesystem::path UnitRecordFile(const std::filesystem::path& fleet, const Unit& unit);
std::filesystem::path UnitLogFile(const std::filesystem::path& fleet, const Unit& unit);
std::filesystem::path UnitCheckLogFile(const std::filesystem::path& fleet, const Unit& unit);

}  // namespace speckle::fleet
