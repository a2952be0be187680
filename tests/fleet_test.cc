// fleet (issue 48): a batch of simulated units calibrated on this machine
// with two workers; a fleet resumes where it stopped without redoing the
// calibrated units; a damaged unit fails alone; a unit's check recording
// gives its check status. (The unit out of the fleet's
// spread: bench/fleet_benchmark.py, seed 1 in the suite with its Slurm run,
// and fleet_spread_test on made-up units.)
#include <gtest/gtest.h>

#include <fstream>

#include "schemas/errors.h"
#include "test_util.h"

namespace speckle::testing {
namespace {

class Fleet : public ::testing::Test {
 protected:
  // One unit: the stock preset, 12 poses of two frames, four walls; its serial in session.json.
  // A check recording of it (folder `name`): walls left out, and its depth scale `scale` times the unit's.
  static void Record(const std::string& serial, int seed, const std::string& name = "", double scale = 1) {
    nlohmann::json scenario = {{"schema_version", 1},
                               {"seed", seed},
                               {"depthboard", {{"poses", 12}, {"frames_per_pose", 2}}},
                               {"planar", {{"snapshots", name.empty() ? 4 : 0}, {"frames_per_snapshot", 1}}},
                               {"ir_chessboard", {{"poses", 0}}}};
    if (scale != 1) scenario["depth_model"] = {{"a", -0.0027681 / scale}, {"b", 3.0163 / scale}};
    const fs::path file = *scratch_ / (serial + name + ".json");
    std::ofstream(file) << scenario.dump();
    const fs::path out = name.empty() ? *scratch_ / "units" / serial : *scratch_ / name;
    const CommandResult r =
        RunTool("record-session", "sim --scenario " + file.string() + " --serial " + serial + " --out " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  static void SetUpTestSuite() {
    scratch_ = new ScratchDir;
    for (int unit = 1; unit <= 3; ++unit) Record("K" + std::to_string(unit), unit);
  }
  static void TearDownTestSuite() { delete scratch_; }
  static ScratchDir* scratch_;
};
ScratchDir* Fleet::scratch_ = nullptr;

TEST_F(Fleet, ARestartRedoesNothingCalibratedAndAnotherFleetsFolderIsRefused) {
  const fs::path out = *scratch_ / "fleet";
  const CommandResult first =
      RunTool("fleet", (*scratch_ / "units").string() + " --out " + out.string() + " --workers 2");
  EXPECT_EQ(first.exit_code, 0) << first.output;
  const nlohmann::json summary = ReadJson(out / "summary-0001" / "fleet.json");
  EXPECT_EQ(summary["schema"], "speckle.fleet");
  ASSERT_EQ(summary["units"].size(), 3u);
  for (const auto& unit : summary["units"]) EXPECT_TRUE(unit["calibrated"].get<bool>()) << unit.dump();
  EXPECT_TRUE(fs::exists(out / "summary-0001" / "fleet.csv"));
  EXPECT_TRUE(fs::exists(out / "summary-0001" / "fleet.html"));
  // A batch killed before K2's record was written: only K2 runs again.
  fs::remove(out / "units" / "K2.json");
  const CommandResult again = RunTool("fleet", (*scratch_ / "units").string() + " --out " + out.string());
  EXPECT_EQ(again.exit_code, 0) << again.output;
  EXPECT_NE(again.output.find("2 of 3 units already calibrated: not run again"), std::string::npos) << again.output;
  EXPECT_NE(again.output.find("[1/1] K2: calibrated"), std::string::npos) << again.output;
  EXPECT_TRUE(fs::exists(out / "summary-0002" / "fleet.json")) << "a new summary; the first is kept";
  // Another fleet's units into this folder are refused by name.
  const CommandResult other = RunTool("fleet", (*scratch_ / "units" / "K1").string() + " --out " + out.string());
  EXPECT_EQ(other.exit_code, 3) << other.output;
}

// A unit whose recording is damaged fails alone: the others are calibrated,
// the summary names the failure and why, and the exit code says so. Each
// unit's check recording gives its check status: K1 recorded again is OK,
// K2's second recording with its depth 1 % off is not.
TEST_F(Fleet, ADamagedUnitFailsAloneAndEachUnitsCheckIsReported) {
  Record("K1", 11, "K1-again");
  Record("K2", 12, "K2-scaled", 1.01);
  const fs::path units = *scratch_ / "damaged-units";
  fs::create_directories(units);
  for (const std::string serial : {"K1", "K2", "K3"})
    fs::copy(*scratch_ / "units" / serial, units / serial, fs::copy_options::recursive);
  fs::resize_file(units / "K3" / "depthboard.h5", 4096);
  const fs::path list = *scratch_ / "fleet.csv";
  std::ofstream(list) << "serial,session\n# three of the bench's units\n"
                      << "K1,damaged-units/K1,K1-again\nK2,damaged-units/K2,K2-scaled\nK3,damaged-units/K3\n";
  const CommandResult r = RunTool("fleet", list.string() + " --out " + (*scratch_ / "damaged").string());
  EXPECT_EQ(r.exit_code, 11) << r.output;
  EXPECT_NE(r.output.find("K3           FAILED"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("depthboard.h5"), std::string::npos) << r.output;
  const nlohmann::json summary = ReadJson(*scratch_ / "damaged" / "summary-0001" / "fleet.json");
  int calibrated = 0;
  for (const auto& unit : summary["units"]) calibrated += unit["calibrated"].get<bool>();
  EXPECT_EQ(calibrated, 2);
  ASSERT_EQ(summary["units"].size(), 3u);
  EXPECT_EQ(summary["units"][0]["check_status"], "OK") << r.output;
  const std::string scaled = summary["units"][1]["check_status"];
  EXPECT_TRUE(scaled == "DEGRADED" || scaled == "RECALIBRATE") << r.output;
  EXPECT_EQ(summary["units"][2]["check_status"], "not checked");
  EXPECT_TRUE(fs::exists(summary["units"][0]["check_folder"].get<std::string>() + "/check.json"));
  std::ifstream csv_file(*scratch_ / "damaged" / "summary-0001" / "fleet.csv");
  const std::string csv((std::istreambuf_iterator<char>(csv_file)), {});
  EXPECT_NE(csv.find(",\"OK\","), std::string::npos) << csv;
  // With K3 repaired the batch resumes; the exit code now says that a check is not OK.
  fs::copy_file(*scratch_ / "units" / "K3" / "depthboard.h5", units / "K3" / "depthboard.h5",
                fs::copy_options::overwrite_existing);
  const CommandResult again = RunTool("fleet", list.string() + " --out " + (*scratch_ / "damaged").string());
  EXPECT_EQ(again.exit_code, 12) << again.output;
}

TEST(FleetUsage, AMissingSessionASerialTwiceOrAPathForASerialIsRefusedByName) {
  ScratchDir s;
  std::ofstream(s / "list") << "A,nowhere\n";
  const CommandResult missing = RunTool("fleet", (s / "list").string() + " --out " + (s / "f").string());
  EXPECT_EQ(missing.exit_code, 3) << missing.output;
  EXPECT_NE(missing.output.find("line 1: "), std::string::npos) << missing.output;
  EXPECT_FALSE(fs::exists(s / "f")) << "nothing is written for a manifest that is refused";
  EXPECT_EQ(RunTool("fleet", (s / "list").string()).exit_code, 2) << "--out is required";
  // A serial that would put the unit's record outside the fleet folder.
  fs::create_directories(s / "unit");
  std::ofstream(s / "unit" / "session.json") << "{}";
  std::ofstream(s / "list") << "../../escape,unit\n";
  const CommandResult escape = RunTool("fleet", (s / "list").string() + " --out " + (s / "f").string());
  EXPECT_EQ(escape.exit_code, 3) << escape.output;
  EXPECT_NE(escape.output.find("serial \"../../escape\""), std::string::npos) << escape.output;
  EXPECT_FALSE(fs::exists(s / "f"));
  std::ofstream(s / "list") << "A,unit,no-such-recording\n";
  const CommandResult check = RunTool("fleet", (s / "list").string() + " --out " + (s / "f").string());
  EXPECT_EQ(check.exit_code, 3) << check.output;
  EXPECT_NE(check.output.find("is not a check recording"), std::string::npos) << check.output;
  std::ofstream(s / "list") << "A,unit,unit\n";
  const CommandResult own = RunTool("fleet", (s / "list").string() + " --out " + (s / "f").string());
  EXPECT_EQ(own.exit_code, 3) << own.output;
  EXPECT_NE(own.output.find("the check recording is the unit's own session"), std::string::npos) << own.output;
  std::ofstream(s / "list") << "A,unit\nA,unit\n";
  const CommandResult twice = RunTool("fleet", (s / "list").string() + " --out " + (s / "f").string());
  EXPECT_EQ(twice.exit_code, 3) << twice.output;
  EXPECT_NE(twice.output.find("serial A is given twice"), std::string::npos) << twice.output;
  // A binary file: its bytes went to the terminal, cut at a NUL (issue 47's outside probe).
  std::ofstream(s / "list", std::ios::binary) << std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16);
  const CommandResult binary = RunTool("fleet", (s / "list").string() + " --out " + (s / "f").string());
  EXPECT_EQ(binary.exit_code, 3) << binary.output;
  EXPECT_NE(binary.output.find("line 1: holds bytes that are not text"), std::string::npos) << binary.output;
  // Slurm asked for with no cluster to take the job: every unit was reported
  // FAILED, pointing at task logs that do not exist, and a summary written
  // (issue 47's outside probe). Now exit 4, the cluster named, no summary.
  std::ofstream(s / "list") << "A,unit\n";
  std::ofstream(s / "empty-slurm.conf");  // refused at once (a missing one is retried for a minute)
  const CommandResult no_cluster =
      RunShell("SLURM_CONF=" + (s / "empty-slurm.conf").string() + " " + (BinDir() / "fleet").string() + " " +
               (s / "list").string() + " --engine slurm --out " + (s / "f").string());
  EXPECT_EQ(no_cluster.exit_code, kExitNoDevice) << no_cluster.output;
  EXPECT_NE(no_cluster.output.find("no unit ran on Slurm"), std::string::npos) << no_cluster.output;
  for (const auto& entry : fs::directory_iterator(s / "f"))
    EXPECT_EQ(entry.path().filename().string().find("summary"), std::string::npos) << entry.path();
}

}  // namespace
}  // namespace speckle::testing
