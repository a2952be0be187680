#include "apps/fleet/fleet_engines.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>

#include "apps/fleet/child_process.h"
#include "apps/fleet/fleet_unit.h"
#include "lab/diagnosis/verdict_text.h"
#include "schemas/atomic_file.h"
#include "schemas/errors.h"

namespace speckle::fleet {
namespace fs = std::filesystem;

void RunLocally(const fs::path& fleet, const Plan& plan, const std::vector<std::size_t>& todo, int workers) {
  std::atomic<int> done{0};
  tbb::task_arena arena(std::max(1, workers));
  arena.execute([&] {
    tbb::parallel_for(
        std::size_t{0}, todo.size(),
        [&](std::size_t k) {
          const UnitRecord r = RunUnit(fleet, plan, todo[k]);
          spdlog::info("[{}/{}] {}: {} in {:.1f} s", ++done, todo.size(), r.serial,
                       r.calibrated ? "calibrated" : "FAILED (" + r.reason + ")", r.seconds);
        },
        tbb::simple_partitioner{});
  });
}

int RunOnSlurm(const fs::path& fleet, const Plan& plan, const std::vector<std::size_t>& todo, int workers,
               const std::string& fleet_tool) {
  fs::create_directories(fleet / "slurm");
  const fs::path script = fleet / "slurm" / "array.sh";
  WriteFileAtomically(script,
                      fmt::format("#!/bin/bash\n# One fleet unit per array task (apps/fleet/fleet_engines.cc).\n"
                                  "exec {} unit {} \"$SLURM_ARRAY_TASK_ID\"\n",
                                  ShellWord(fleet_tool), ShellWord(fs::absolute(fleet).string())));
  std::string indices;
  for (std::size_t i : todo) indices += (indices.empty() ? "" : ",") + std::to_string(i);
  const std::vector<std::string> sbatch{"sbatch",
                                        "--wait",
                                        "--job-name=speckle-fleet",
                                        fmt::format("--array={}%{}", indices, std::max(1, workers)),
                                        fmt::format("--cpus-per-task={}", plan.threads_per_unit),
                                        "--output=" + (fs::absolute(fleet) / "slurm" / "%a.out").string(),
                                        script.string()};
  spdlog::info("{} units submitted to Slurm as one job array, {} at a time (sbatch --wait)", todo.size(), workers);
  try {
    return RunLogged(sbatch, fleet / "slurm" / "sbatch.log");
  } catch (const std::runtime_error& e) {  // not installed
    throw DeviceError(std::string(e.what()) +
                      " (Slurm's client: Debian's slurm-client); or run without --engine slurm");
  }
}

}  // namespace speckle::fleet
