// Scenario files: the shipped examples stay valid, defaults round-trip, and
// the simulator is deterministic from its seed.
#include <gtest/gtest.h>

#include <fstream>
#include <iostream>
#include <map>

#include "schemas/errors.h"
#include "simulator/scenario_usability.h"
#include "simulator/session_simulator.h"
#include "test_util.h"

namespace speckle::sim {
namespace {

TEST(Scenario, ShippedExamplesParse) {
  int parsed = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::path(SPECKLE_SOURCE_DIR) / "examples" / "scenarios")) {
    std::ifstream in(entry.path());
    EXPECT_NO_THROW(ScenarioFromJson(nlohmann::json::parse(in), entry.path().string())) << entry.path();
    ++parsed;
  }
  EXPECT_GE(parsed, 2);
}

// Every shipped scenario, drawn at seeds 1-30 as the benchmarks draw them,
// passes the usability check: it refuses no session the tool was built on.
TEST(Scenario, ShippedExamplesAreUsableAtEverySeed) {
  double smallest_square_px = 1e9;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::path(SPECKLE_SOURCE_DIR) / "examples" / "scenarios")) {
    std::ifstream in(entry.path());
    nlohmann::json json = nlohmann::json::parse(in);
    for (int seed = 1; seed <= 30; ++seed) {
      json["seed"] = seed;
      const Scenario s = ScenarioFromJson(json, entry.path().string());
      EXPECT_NO_THROW(CheckUsable(s, entry.path().string())) << entry.path() << " seed " << seed;
      if (s.depthboard.poses > 0)
        smallest_square_px =
            std::min(smallest_square_px, OpticsFor(s).colour.fx * s.rig.square_size_m / s.depthboard.max_depth_m);
    }
  }
  EXPECT_GE(smallest_square_px, kMinSquarePx);
  std::cout << "smallest square at the farthest pose: " << smallest_square_px << " px\n";
}

TEST(Scenario, DefaultsRoundTripThroughJson) {
  const Scenario defaults;
  const Scenario again = ScenarioFromJson(ToJson(defaults), "test");
  EXPECT_EQ(ToJson(again), ToJson(defaults));
}

TEST(Scenario, NewerVersionRejected) {
  EXPECT_THROW(ScenarioFromJson({{"schema_version", 2}}, "test"), SchemaVersionError);
}

TEST(Simulator, SameSeedSameFrames) {
  const Scenario s = ScenarioFromJson({{"depthboard", {{"poses", 2}}}, {"planar", {{"snapshots", 1}}}}, "test");
  const SessionSimulator a(s), b(s);
  const auto& spec = a.Frames(SimRecording::kDepthboard).at(3);
  const SimFrame fa = a.Render(SimRecording::kDepthboard, spec), fb = b.Render(SimRecording::kDepthboard, spec);
  EXPECT_EQ(cv::norm(fa.raw_depth, fb.raw_depth, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(fa.colour_rgb, fb.colour_rgb, cv::NORM_INF), 0);
}

// A still pose's frames share one rendering of the scene (the simulator
// keeps the last): frames asked for in any order, poses interleaved, equal
// the same frames rendered alone by a fresh simulator.
TEST(Simulator, FramesInAnyOrderEqualFramesRenderedAlone) {
  const Scenario s = ScenarioFromJson({{"depthboard", {{"poses", 2}, {"frames_per_pose", 2}}},
                                       {"planar", {{"snapshots", 2}, {"frames_per_snapshot", 2}}},
                                       {"ir_chessboard", {{"poses", 2}, {"frames_per_pose", 2}}}},
                                      "test");
  const std::vector<SimRecording> recordings{SimRecording::kDepthboard, SimRecording::kPlanar,
                                             SimRecording::kIrChessboard};
  // Frame i of each recording, each the first its simulator renders there.
  std::map<std::pair<SimRecording, std::size_t>, SimFrame> alone;
  for (std::size_t i = 0; i < 4; ++i) {
    const SessionSimulator fresh(s);
    for (const SimRecording which : recordings) alone[{which, i}] = fresh.Render(which, fresh.Frames(which).at(i));
  }
  const SessionSimulator shared(s);
  for (const std::size_t i : {0u, 2u, 1u, 3u, 0u}) {
    for (const SimRecording which : recordings) {
      const SimFrame again = shared.Render(which, shared.Frames(which).at(i));
      const SimFrame& first = alone.at({which, i});
      for (const auto& [a, b] : {std::pair(again.raw_depth, first.raw_depth),
                                 std::pair(again.colour_rgb, first.colour_rgb), std::pair(again.ir, first.ir)}) {
        ASSERT_EQ(a.size(), b.size()) << "recording " << static_cast<int>(which) << " frame " << i;
        if (!a.empty())
          EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0) << "recording " << static_cast<int>(which) << " frame " << i;
      }
    }
  }
}

TEST(Simulator, RawValuesFollowTheReciprocalForm) {
  // A fronto-parallel wall at 1 m, no noise: every valid pixel reads
  // round((1/z - b) / a) for its true z.
  Scenario s = ScenarioFromJson(
      {{"depthboard", {{"poses", 0}}},
       {"planar", {{"snapshots", 1}, {"min_depth_m", 1.0}, {"max_depth_m", 1.0}, {"clutter_probability", 0}}}},
      "test");
  s.depth.raw_noise_sigma = 0;
  const SessionSimulator sim(s);
  const SimFrame f = sim.Render(SimRecording::kPlanar, sim.Frames(SimRecording::kPlanar).at(0));
  const int expected = static_cast<int>(std::round((1.0 / 1.0 - s.depth.b) / s.depth.a));
  EXPECT_EQ(f.raw_depth.at<std::uint16_t>(240, 320), expected);
  EXPECT_EQ(f.raw_depth.at<std::uint16_t>(10, 10), expected);
}

}  // namespace
}  // namespace speckle::sim

namespace speckle::sim {
namespace {

TEST(Scenario, CameraOverridesReplaceThePreset) {
  const Scenario s =
      ScenarioFromJson({{"cameras",
                         {{"ir", {{"intrinsics", {600, 601, 320, 240}}, {"distortion", {0, 0, 0, 0, 0}}}},
                          {"colour_from_ir_m", {-0.03, 0, 0}},
                          {"projector_in_ir_m", {0.08, 0, 0}}}}},
                       "test");
  const SensorOptics optics = OpticsFor(s);
  EXPECT_EQ(optics.ir.fx, 600);
  EXPECT_EQ(optics.ir.cy, 240);
  EXPECT_NEAR(optics.ir.Project({0.1, 0.0, 1.0}).x(), 320 + 60, 1e-9) << "no distortion after the override";
  EXPECT_EQ(optics.colour_from_ir.translation().x(), -0.03);
  EXPECT_EQ(optics.projector_in_ir.x(), 0.08);
  EXPECT_EQ(optics.colour.fx, StockOptics().colour.fx) << "the colour camera keeps the preset";
}

// Issue 47: a colour camera a kilometre from the IR camera (millimetres
// typed as metres) rendered boards nowhere, and the refusal named no key.
TEST(Scenario, AnOffsetBeyondTheSensorIsRefusedNamingTheKey) {
  for (const char* key : {"colour_from_ir_m", "projector_in_ir_m"}) {
    try {
      ScenarioFromJson({{"cameras", {{key, {25, 0, 0}}}}}, "sc.json");
      FAIL() << key;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("sc.json.cameras.") + key +
                                           ": expected an offset within the "
                                           "sensor, at most 0.5 m"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(Scenario, WrongLengthArrayIsNamed) {
  try {
    ScenarioFromJson({{"cameras", {{"ir", {{"distortion", {0.1, 0.2}}}}}}}, "sc.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sc.json.cameras.ir.distortion: expected 5 numbers"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace speckle::sim
