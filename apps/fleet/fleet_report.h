#pragma once
// The fleet summary: one row per unit (model, held-out / floor, depth sigma
// at 1 m, conclusion, plausibility, flags) as fleet.json, fleet.csv and
// fleet.html in a new FLEET/summary-NNNN folder, and the same on the terminal.
#include <filesystem>
#include <string>
#include <vector>

#include "apps/fleet/fleet_spread.h"
#include "apps/fleet/fleet_unit.h"

namespace speckle::fleet {

inline constexpr int kFleetSchemaVersion = 2;  // 2: each unit's check

struct Summary {
  std::vector<UnitRecord> units;  // in the plan's order; a unit never run has calibrated false and a reason
  std::vector<OutOfSpread> out_of_spread;
  SpreadOptions spread;
  std::string engine;
  double seconds = 0;
};

std::string TerminalTable(const Summary& s);
// Writes the folder aside and renames it into place; returns where.
std::filesystem::path WriteSummary(const std::filesystem::path& fleet, const Summary& s);

}  // namespace speckle::fleet
