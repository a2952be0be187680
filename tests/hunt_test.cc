// The model lab's Must-show on simulated sessions with a hidden effect the
// pipeline is not told about: the top-ranked candidate is that effect, and
// refitting with it brings the held-out RMS within 15 % of the noise floor.
// Each case records a session, calibrates it and refits it: one to five
// minutes each.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>

#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;
using nlohmann::json;

struct Hunt {
  const char* scenario;  // examples/scenarios/<name>.json
  const char* effect;    // what the diagnosis must recommend
  const char* refit;     // refit's arguments that add it
};

std::ostream& operator<<(std::ostream& out, const Hunt& h) { return out << h.scenario; }

// The default session size: with fewer board and IR views the cameras'
// calibration errors leave spatial structure in the residuals that the
// diagnosis rightly reports (see the closing notes of issue 5).
fs::path RecordSession(const fs::path& dir, const std::string& scenario_name, std::uint64_t seed,
                       const json& overrides = json::object()) {
  json scenario = ReadJson(fs::path(SPECKLE_SOURCE_DIR) / "examples" / "scenarios" / (scenario_name + ".json"));
  scenario["seed"] = seed;
  scenario.merge_patch(overrides);
  std::ofstream(dir / "scenario.json") << scenario.dump();
  const auto r = RunTool("record-session",
                         "sim --scenario " + (dir / "scenario.json").string() + " --out " + (dir / "s").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return dir / "s";
}

fs::path LatestVersion(const fs::path& session) {
  fs::path latest;
  for (const auto& e : fs::directory_iterator(session / "calibrations"))
    if (latest.empty() || e.path().filename() > latest.filename()) latest = e.path();
  return latest;
}

json LatestReport(const fs::path& session) { return ReadJson(LatestVersion(session) / "report.json"); }

// Runs a tool on the session and returns the new version's diagnosis.
json Diagnosed(const std::string& tool, const fs::path& session, const std::string& arguments = "") {
  const auto r = RunTool(tool, session.string() + arguments);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return LatestReport(session)["diagnosis"];
}

class HiddenEffect : public ::testing::TestWithParam<Hunt> {};

TEST_P(HiddenEffect, IsFoundAndAddingItReachesTheNoiseFloor) {
  const Hunt& hunt = GetParam();
  ScratchDir scratch;
  const fs::path session = RecordSession(scratch.path(), hunt.scenario, 1);
  const json before = Diagnosed("run-pipeline", session);
  EXPECT_FALSE(before["complete"].get<bool>()) << before["verdict"];
  ASSERT_FALSE(before["candidates"].empty());
  EXPECT_EQ(before["candidates"][0]["name"], hunt.effect) << before["verdict"];
  EXPECT_EQ(before["recommended"], hunt.effect) << before["verdict"];
  const json after = Diagnosed("refit", session, std::string(" ") + hunt.refit);
  EXPECT_LE(after["ratio_to_floor"].get<double>(), 1.15) << after["verdict"];
  EXPECT_TRUE(after["recommended"].is_null()) << after["verdict"];
  EXPECT_LT(after["held_out_raw"].get<double>(), before["held_out_raw"].get<double>());
}

// The pattern needs more poses than a user records (the hunt benchmark's
// pixel_pattern row misses at 20; bench/results/hunt.md): here 160 poses, no walls. The
// other catalogue effects are checked at a user's 20 poses by the hunt
// benchmark's seed 1 in CI (tests/CMakeLists.txt, hunt_benchmark_*_seed1);
// 60-pose copies of its albedo_bias and depth_grid_offset rows ran here too
// and cost 6.5 of a CI run's minutes.
INSTANTIATE_TEST_SUITE_P(Catalogue, HiddenEffect,
                         ::testing::Values(Hunt{"effect_disparity_pattern_boards_only", "disparity_pattern",
                                                "--add-effect disparity_pattern"}),
                         [](const auto& info) { return std::string(info.param.effect); });

// The warm-up drift of effect_thermal_drift seen through an OpenNI-like
// driver's millimetres: the drift is in raw steps, so in millimetres it grows
// with depth squared. The diagnosis of the linear_mm model finds it as
// thermal_drift_mm, and its refit ends at the noise floor like the raw hunts
// (measured: held out 5.70 -> 0.636 mm, 0.91 x floor; the catalogue's
// thermal_drift, one offset per time, left 2.26 mm, 3.0 x).
TEST(HiddenEffectInMillimetres, ThermalDriftIsFoundInALinearMmSession) {
  ScratchDir scratch;
  const fs::path session = RecordSession(scratch.path(), "effect_thermal_drift_mm", 1);
  const json before = Diagnosed("run-pipeline", session);
  EXPECT_EQ(ReadJson(LatestVersion(session) / "calibration.json")["model"]["base_form"], "linear_mm");
  EXPECT_FALSE(before["complete"].get<bool>()) << before["verdict"];
  ASSERT_FALSE(before["candidates"].empty());
  EXPECT_EQ(before["candidates"][0]["name"], "thermal_drift_mm") << before["verdict"];
  EXPECT_EQ(before["recommended"], "thermal_drift_mm") << before["verdict"];
  // The verdict's own command, pasted as the user would: it names refit
  // beside run-pipeline (the tools are not on PATH), in another directory.
  ASSERT_FALSE(before["next_steps"].empty()) << before["verdict"];
  const std::string command = before["next_steps"][0]["command"];
  EXPECT_EQ(command, (BinDir() / "refit").string() + " " + session.string() + " --add-effect thermal_drift_mm");
  const CommandResult pasted = RunShell("cd / && " + command);
  ASSERT_EQ(pasted.exit_code, 0) << pasted.output;
  // The promise comes with its spread over poses, and the refit says whether
  // it held (issue 47: "cuts ... to 1.128" was stated as fact; 1.166 came).
  EXPECT_NE(before["verdict"].get<std::string>().find("90 % interval"), std::string::npos) << before["verdict"];
  EXPECT_NE(pasted.output.find("promised     v0001's verdict: about"), std::string::npos) << pasted.output;
  // Inside it, or better (the joint calibration's refit fits every sample: 0.539 mm against 0.565-0.754
  // promised on 2026-12-07); never worse.
  EXPECT_TRUE(pasted.output.find("inside it") != std::string::npos ||
              pasted.output.find("below it: better than promised") != std::string::npos)
      << pasted.output;
  const json after = LatestReport(session)["diagnosis"];
  EXPECT_LT(after["held_out_raw"].get<double>(), 0.5 * before["held_out_raw"].get<double>()) << after["verdict"];
  EXPECT_LE(after["ratio_to_floor"].get<double>(), 1.15) << after["verdict"];
  EXPECT_TRUE(after["recommended"].is_null()) << after["verdict"];
}

// Depth exposed 33 ms after colour while the board sways at 0.2 m/s: the
// extrinsics fit the delay from the board's outline, the diagnosis
// recommends capture_time_offset, and its refit finds the same delay from the
// raw values, ending within 15 % of the noise floor like the others.
TEST(HiddenEffectCaptureTime, IsFoundAndTheDepthModelAgreesWithTheExtrinsicsOnTheDelay) {
  ScratchDir scratch;
  const fs::path session = RecordSession(scratch.path(), "effect_capture_time_offset", 1);
  const json before = Diagnosed("run-pipeline", session);
  ASSERT_FALSE(before["candidates"].empty());
  EXPECT_EQ(before["candidates"][0]["name"], "capture_time_offset") << before["verdict"];
  EXPECT_EQ(before["recommended"], "capture_time_offset") << before["verdict"];
  const json after = Diagnosed("refit", session, " --add-effect capture_time_offset");
  EXPECT_LT(after["held_out_raw"].get<double>(), 0.4 * before["held_out_raw"].get<double>()) << after["verdict"];
  EXPECT_LE(after["ratio_to_floor"].get<double>(), 1.15) << after["verdict"];
  EXPECT_TRUE(after["recommended"].is_null()) << after["verdict"];
  const json c = ReadJson(LatestVersion(session) / "calibration.json");
  double delay = 0, sigma = 0;
  for (const auto& p : c["model"]["parameters"])
    if (p["block"] == "capture_time_offset") delay = p["value"], sigma = p["sigma"];
  EXPECT_NEAR(delay, 0.033, std::max(3 * sigma, 0.002)) << "the scenario's offset_s";
  EXPECT_NEAR(delay, c["cameras"]["depth_from_colour"]["depth_delay_s"].get<double>(), 0.003)
      << "the depth model and the extrinsics measure the same delay";
}

// The same pattern with wall snapshots: the undistortion grid built from the
// walls absorbs most of it (held-out 1.135 -> 0.267 raw on seed 1 with the
// separate steps; 0.983 -> 0.388 in the joint calibration, the default since
// 2026-12-07, whose cameras take up some of the pattern first). Before the
// hyperboloid's vertex was kept on the wall, three barely billowing walls got
// true raw values 15-20 raw low and the grid made the boards 5 times worse.
TEST(HiddenEffectWithWalls, TheUndistortionGridAbsorbsTheDisparityPattern) {
  ScratchDir scratch;
  const fs::path session = RecordSession(scratch.path(), "effect_disparity_pattern", 1);
  const auto r = RunTool("run-pipeline", session.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json report = LatestReport(session);
  const double without = FitHeldOutRaw(report, "reciprocal"), with = FitHeldOutRaw(report, "reciprocal +undistortion");
  ASSERT_GT(without, 0);
  EXPECT_LT(with, 0.5 * without) << "most of it";
  // The verdict's "refit --add-effect" keeps the grid the current model
  // chose: the candidate was judged on the samples it undistorted.
  ASSERT_TRUE(ReadJson(LatestVersion(session) / "calibration.json")["undistortion_grid"].is_string());
  const auto refit = RunTool("refit", session.string() + " --add-effect albedo_bias");
  ASSERT_EQ(refit.exit_code, 0) << refit.output;
  const json calibration = ReadJson(LatestVersion(session) / "calibration.json");
  EXPECT_EQ(calibration["model_spec"]["undistortion"], "on");
  EXPECT_TRUE(calibration["undistortion_grid"].is_string());
}

}  // namespace
}  // namespace speckle
