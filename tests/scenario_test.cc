// Scenario files: the shipped examples stay valid, defaults round-trip, and
// the simulator is deterministic from its seed.
#include <gtest/gtest.h>

#include <fstream>

#include "schemas/errors.h"
#include "simulator/session_simulator.h"
#include "test_util.h"

namespace speckle::sim {
namespace {

TEST(Scenario, ShippedExamplesParse) {
  int parsed = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(SPECKLE_SOURCE_DIR) / "examples" / "scenarios")) {
    std::ifstream in(entry.path());
    EXPECT_NO_THROW(ScenarioFromJson(nlohmann::json::parse(in), entry.path().string())) << entry.path();
    ++parsed;
  }
  EXPECT_GE(parsed, 2);
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

TEST(Simulator, RawValuesFollowTheReciprocalForm) {
  // A fronto-parallel wall at 1 m, no noise: every valid pixel reads
  // round((1/z - b) / a) for its true z.
  Scenario s = ScenarioFromJson({{"depthboard", {{"poses", 0}}}, {"planar", {{"snapshots", 1}, {"min_depth_m", 1.0},
                                  {"max_depth_m", 1.0}, {"clutter_probability", 0}}}}, "test");
  s.depth.raw_noise_sigma = 0;
  const SessionSimulator sim(s);
  const SimFrame f = sim.Render(SimRecording::kPlanar, sim.Frames(SimRecording::kPlanar).at(0));
  const int expected = static_cast<int>(std::round((1.0 / 1.0 - s.depth.b) / s.depth.a));
  EXPECT_EQ(f.raw_depth.at<std::uint16_t>(240, 320), expected);
  EXPECT_EQ(f.raw_depth.at<std::uint16_t>(10, 10), expected);
}

}  // namespace
}  // namespace speckle::sim
