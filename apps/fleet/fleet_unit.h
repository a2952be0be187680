#pragma once
// One unit of a fleet: its session calibrated by run-pipeline (a child
// process, its output in the fleet's logs/), and what the fleet summary needs
// of the version it wrote, kept as units/SERIAL.json. That record is how a
// restarted fleet knows the unit is done: it is written whole or not at all.
#include <optional>
#include <string>
#include <vector>

#include "apps/fleet/fleet_plan.h"

namespace speckle::fleet {

inline constexpr int kUnitSchemaVersion = 2;  // 2: the check

struct Parameter {
  std::string name;             // "model.b", "depth.fx", "depth_from_colour.tx", ...
  double value = 0, sigma = 0;  // sigma 0: the calibration states none
};

struct UnitRecord {
  std::string serial, session;
  bool calibrated = false;
  int exit_code = 0;
  std::string reason;  // why it failed: the run's last error line
  std::string version, model, conclusion;
  double held_out_to_floor = 0, depth_sigma_mm_at_1m = 0;
  std::vector<std::string> plausibility_problems;
  std::vector<Parameter> parameters;
  // `check` of the new calibration on the unit's check recording: "OK",
  // "DEGRADED", "RECALIBRATE", "CANNOT JUDGE", "not checked" (no check
  // recording in the manifest), or "check failed: WHY"; its folder.
  std::string check_status = "not checked", check_folder;
  double seconds = 0;
};

// Calibrates plan.units[index], checks the new calibration on the unit's
// check recording when it has one, and writes its record; a failed run is a
// record too (calibrated false), not an exception.
UnitRecord RunUnit(const std::filesystem::path& fleet, const Plan& plan, std::size_t index);

// The check said the calibration holds on the unit's second recording, or
// there was none to check it on.
bool CheckPassedOrNotAsked(const UnitRecord& r);
// The check could not run or ended in error: a restart runs the unit again.
bool CheckFailed(const UnitRecord& r);

nlohmann::json ToJson(const UnitRecord& r);
// nullopt when the unit has no record yet; throws InputError for one it cannot read.
std::optional<UnitRecord> ReadUnitRecord(const std::filesystem::path& fleet, const Unit& unit);

}  // namespace speckle::fleet
