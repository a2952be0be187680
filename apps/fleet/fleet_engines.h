#pragma once
// Where a fleet's units run. Both engines run the same thing per unit
// (RunUnit, in-process or as `fleet unit FLEET INDEX`), so a fleet gives the
// same records whichever ran it.
#include <filesystem>
#include <string>
#include <vector>

#include "apps/fleet/fleet_plan.h"

namespace speckle::fleet {

// The embedded engine: `workers` units at a time on this machine (a TBB arena).
void RunLocally(const std::filesystem::path& fleet, const Plan& plan, const std::vector<std::size_t>& todo,
                int workers);

// Slurm: one job array through `sbatch --wait`, at most `workers` tasks at a
// time, each `fleet_tool unit FLEET INDEX`; the tasks' output in
// FLEET/slurm/. Returns sbatch's exit code (non-zero when it could not
// submit, or a task ended without writing its record).
int RunOnSlurm(const std::filesystem::path& fleet, const Plan& plan, const std::vector<std::size_t>& todo, int workers,
               const std::string& fleet_tool);

}  // namespace speckle::fleet
