// fleet MANIFEST --out FLEET: many sensor units' sessions calibrated in one
// batch (each by run-pipeline), one summary, and the units whose parameters
// lie outside the rest of the fleet's spread named. Runs here with N workers,
// or on Slurm as one job array; a killed fleet resumes where it stopped.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <thread>

#include "apps/cli_main.h"
#include "apps/fleet/fleet_engines.h"
#include "apps/fleet/fleet_report.h"
#include "schemas/atomic_file.h"
#include "schemas/staging.h"

namespace {

using namespace speckle;
using namespace speckle::fleet;
namespace fs = std::filesystem;

constexpr int kExitOutOfSpread = 10, kExitUnitsFailed = 11, kExitCheckNotOk = 12;

struct Flags {
  std::string manifest, out, engine = "local";
  int workers = 0;  // 0: one per core
  std::vector<std::string> pipeline_args;
  std::string self, run_pipeline, check;
  std::string unit_fleet;  // `fleet unit FLEET INDEX`
  std::size_t unit_index = 0;
};

// A new fleet folder gets its plan; an existing one must hold this fleet's
// plan (a restart), which then governs.
int Cores() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }
int Workers(const Flags& flags) { return flags.workers > 0 ? flags.workers : Cores(); }

Plan PlanFor(const Flags& flags, const fs::path& fleet) {
  Plan wanted{ReadManifest(flags.manifest), flags.run_pipeline, flags.check, flags.pipeline_args};
  wanted.threads_per_unit = std::max(1, Cores() / Workers(flags));
  if (!fs::exists(fleet)) {
    fs::create_directories(fleet);
    WriteFileAtomically(PlanFile(fleet), ToJson(wanted).dump(1) + "\n");
    return wanted;
  }
  if (!fs::exists(PlanFile(fleet)))
    throw InputError(fleet.string() + ": exists and is not a fleet folder (no fleet_plan.json); choose a new --out");
  const Plan plan = ReadPlan(PlanFile(fleet));
  const auto units = [](const Plan& p) { return ToJson(p)["units"]; };
  if (units(plan) != units(wanted) || plan.pipeline_args != wanted.pipeline_args)
    throw InputError(fleet.string() + ": holds another fleet (other units or --pipeline-arg); choose a new --out");
  spdlog::info("{}: resuming the fleet begun there", fleet.string());
  return plan;
}

std::vector<std::size_t> UnitsToRun(const fs::path& fleet, const Plan& plan) {
  std::vector<std::size_t> todo;
  int failed = 0;
  for (std::size_t i = 0; i < plan.units.size(); ++i) {
    const auto record = ReadUnitRecord(fleet, plan.units[i]);
    if (record && record->calibrated && !CheckFailed(*record)) continue;
    failed += record.has_value();
    todo.push_back(i);
  }
  const std::size_t done = plan.units.size() - todo.size();
  if (done > 0) spdlog::info("{} of {} units already calibrated: not run again", done, plan.units.size());
  if (failed > 0) spdlog::info("{} units that failed (or whose check failed) before are run again", failed);
  return todo;
}

std::vector<UnitRecord> Records(const fs::path& fleet, const Plan& plan, const std::string& engine) {
  std::vector<UnitRecord> out;
  for (const auto& unit : plan.units) {
    if (auto r = ReadUnitRecord(fleet, unit)) {
      out.push_back(*r);
      continue;
    }
    UnitRecord missing;
    missing.serial = unit.serial, missing.session = unit.session.string();
    missing.reason =
        engine == "slurm" ? "its Slurm task ended without a record (slurm/INDEX.out in the fleet folder)" : "not run";
    out.push_back(missing);
  }
  return out;
}

// sbatch that submitted nothing (no cluster configured, slurmctld down)
// left every unit "FAILED" with a pointer to task logs that do not exist,
// and a summary of a fleet that never ran (issue 47's outside probe). No
// task's log: the cluster is the missing device, and nothing is summarized.
void RequireAnyTaskRan(const fs::path& fleet, int sbatch_code) {
  for (const auto& entry : fs::directory_iterator(fleet / "slurm"))
    if (entry.path().extension() == ".out") return;
  std::ifstream log(fleet / "slurm" / "sbatch.log");
  std::string last;  // sbatch's last word is its fatal one
  for (std::string line; std::getline(log, line);)
    if (!line.empty()) last = line;
  throw DeviceError(
      fmt::format("sbatch ended with {} and no unit ran on Slurm ({}: \"{}\"): is a cluster up "
                  "(sinfo)? Nothing was calibrated; run the same command once it is, or without "
                  "--engine slurm",
                  sbatch_code, (fleet / "slurm" / "sbatch.log").string(), last));
}

int Run(const Flags& flags) {
  const auto start = std::chrono::steady_clock::now();
  const fs::path fleet = NormalizeOutPath(flags.out, "--out");
  const Plan plan = PlanFor(flags, fleet);
  const std::vector<std::size_t> todo = UnitsToRun(fleet, plan);
  const int workers = Workers(flags);
  if (!todo.empty() && flags.engine == "slurm") {
    if (const int code = RunOnSlurm(fleet, plan, todo, workers, flags.self); code != 0) {
      RequireAnyTaskRan(fleet, code);
      spdlog::warn("sbatch ended with {} (its output: {})", code, (fleet / "slurm" / "sbatch.log").string());
    }
  } else if (!todo.empty()) {
    RunLocally(fleet, plan, todo, workers);
  }
  Summary s{Records(fleet, plan, flags.engine), {}, {}, flags.engine};
  s.out_of_spread = FindOutOfSpread(s.units, s.spread);
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << TerminalTable(s);
  for (const auto& f : s.out_of_spread)
    std::cout << fmt::format(
        "out of spread {}: {} = {:.6g} ± {:.2g}; the other units' mean {:.6g}, their spread beyond their sigmas "
        "{:.2g}: "
        "{:+.1f} sigma (beyond {:.1f})\n",
        f.serial, f.parameter, f.value, f.sigma, f.fleet_mean, f.fleet_spread, f.z, f.threshold);
  std::cout << "summary      " << WriteSummary(fleet, s).string() << " (fleet.json, fleet.csv, fleet.html)\n";
  const auto any = [&](auto pred) { return std::any_of(s.units.begin(), s.units.end(), pred); };
  if (any([](const UnitRecord& u) { return !u.calibrated; })) return kExitUnitsFailed;
  if (any([](const UnitRecord& u) { return !CheckPassedOrNotAsked(u); })) return kExitCheckNotOk;
  return s.out_of_spread.empty() ? kExitOk : kExitOutOfSpread;
}

int RunOneUnit(const Flags& flags) {
  const Plan plan = ReadPlan(PlanFile(flags.unit_fleet));
  if (flags.unit_index >= plan.units.size())
    throw InputError(
        fmt::format("{}: unit index {} of {} units", flags.unit_fleet, flags.unit_index, plan.units.size()));
  const UnitRecord r = RunUnit(flags.unit_fleet, plan, flags.unit_index);
  std::cout << r.serial << ": " << (r.calibrated ? "calibrated" : "FAILED: " + r.reason) << "\n";
  return kExitOk;  // a failed unit is a record, not a failed task
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Calibrate many sensor units' sessions in one batch: one summary, and the units out of the fleet's "
      "spread named."};
  Flags flags;
  // Absolute when called by a path: a Slurm task may start in another folder; on PATH, by name.
  const auto beside = [&](const std::string& tool) {
    const std::string path = ToolBeside(argv[0], tool);
    return path.find('/') == std::string::npos ? path : fs::absolute(path).string();
  };
  flags.self = beside("fleet");
  flags.run_pipeline = beside("run-pipeline");
  flags.check = beside("check");
  app.add_option("MANIFEST", flags.manifest,
                 "a folder of sessions, or a file of \"serial,session[,check_recording]\" lines (a check "
                 "recording: a second recording of the unit that `check` scores its new calibration on)");
  app.add_option("--out", flags.out, "the fleet folder: created, or one this fleet began (it resumes)");
  app.add_option("--workers", flags.workers, "units at a time (0: one per core)")->check(CLI::Range(0, 1024));
  app.add_option("--engine", flags.engine, "local (this machine) or slurm (one job array via sbatch)")
      ->check(CLI::IsMember({"local", "slurm"}));
  app.add_option("--pipeline-arg", flags.pipeline_args, "passed to every unit's run-pipeline (repeatable)")
      ->allow_extra_args(false);
  CLI::App* unit = app.add_subcommand("unit", "run one unit of a fleet folder's plan (what each Slurm task runs)");
  unit->add_option("FLEET", flags.unit_fleet)->required();
  unit->add_option("INDEX", flags.unit_index)->required();
  app.footer(
      "Exit codes: 0 every unit calibrated, checked OK where it has a check recording, and none out of spread; "
      "10 a unit out of the fleet's spread; 11 a unit failed (the others are done); 12 a unit's check is not OK "
      "(DEGRADED, RECALIBRATE, cannot judge or failed); 2 usage; 3 bad input.");
  return RunCli("fleet", app, argc, argv, [&] {
    if (*unit) return RunOneUnit(flags);
    if (!flags.manifest.empty() && !flags.out.empty()) return Run(flags);
    std::cerr << "fleet: MANIFEST and --out are required (run with --help)\n";
    return kExitUsage;
  });
}
