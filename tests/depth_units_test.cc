// Depth units end to end: the one no-reading rule, the simulator's
// millimetre output against its truth, the base form a session's units take,
// and the stamp pairing and unit detection the TUM and ROS bag imports use.
#include <gtest/gtest.h>

#include <cmath>

#include "lab/model_spec.h"
#include "recorder/sources/rosbag_source.h"
#include "recorder/sources/stamp_pairing.h"
#include "schemas/depth_reading.h"
#include "schemas/errors.h"
#include "simulator/session_simulator.h"
#include "stages/depth_region.h"

namespace speckle {
namespace {

TEST(DepthReading, NoReadingFollowsTheUnits) {
  const DepthReading raw(DepthUnits::kRaw11Bit), mm(DepthUnits::kMillimetre);
  EXPECT_EQ(raw.NoReadingValue(), 2047);
  EXPECT_EQ(mm.NoReadingValue(), 0);
  EXPECT_TRUE(raw.IsReading(1000));
  EXPECT_FALSE(raw.IsReading(2047));
  EXPECT_FALSE(raw.IsReading(0));
  EXPECT_TRUE(mm.IsReading(2047));  // 2.047 m is a reading in millimetres
  EXPECT_TRUE(mm.IsReading(5000));
  EXPECT_FALSE(mm.IsReading(0));
}

TEST(DepthReading, MillimetreStepsGrowWithDepthSquared) {
  const DepthReading mm(DepthUnits::kMillimetre);
  // One raw step of the stock Kinect: about 2.8 mm at 1 m, 11 mm at 2 m.
  EXPECT_NEAR(mm.UnitsPerRawStep(1000), 2.77, 0.01);
  EXPECT_NEAR(mm.UnitsPerRawStep(2000) / mm.UnitsPerRawStep(1000), 4, 1e-9);
  // On the step scale one raw step is one unit at any depth.
  for (double z : {700.0, 1500.0, 2800.0})
    EXPECT_NEAR(mm.StepValue(z + mm.UnitsPerRawStep(z)) - mm.StepValue(z), 1, 0.01);
  EXPECT_EQ(DepthReading(DepthUnits::kRaw11Bit).UnitsPerRawStep(800), 1);
}

TEST(DepthReading, MasksTheUnitsNoReading) {
  cv::Mat depth = (cv::Mat_<std::uint16_t>(1, 4) << 0, 2047, 900, 3000);
  const cv::Mat raw_none = NoReadingMask(depth, DepthReading(DepthUnits::kRaw11Bit));
  const cv::Mat mm_none = NoReadingMask(depth, DepthReading(DepthUnits::kMillimetre));
  EXPECT_EQ(raw_none.at<std::uint8_t>(0, 1), 255);
  EXPECT_EQ(raw_none.at<std::uint8_t>(0, 3), 255);  // beyond 11 bits
  EXPECT_EQ(mm_none.at<std::uint8_t>(0, 0), 255);
  EXPECT_EQ(mm_none.at<std::uint8_t>(0, 1), 0);
  EXPECT_EQ(mm_none.at<std::uint8_t>(0, 3), 0);
}

// The simulator's millimetres are the driver's conversion of each raw value
// it would have reported: 0 where the raw frame has 2047, and elsewhere
// within a raw step (plus rounding) of the true depth through mm_gain/offset.
TEST(SimulatedMillimetres, AreTheDriversConversionOfTheRawFrame) {
  const auto scenario_json = [](bool mm) {
    nlohmann::json j = {{"depthboard", {{"poses", 2}, {"frames_per_pose", 1}}},
                        {"planar", {{"snapshots", 0}}},
                        {"ir_chessboard", {{"poses", 0}}},
                        {"depth_model", {{"raw_noise_sigma", 0}}}};
    if (mm) j["depth_model"].update({{"units", "millimetre"}, {"mm_gain", 1.02}, {"mm_offset_m", 0.01}});
    return sim::ScenarioFromJson(j, "test");
  };
  const sim::SessionSimulator raw_sim(scenario_json(false)), mm_sim(scenario_json(true));
  const auto& spec = raw_sim.Frames(sim::SimRecording::kDepthboard).at(1);
  const cv::Mat raw = raw_sim.Render(sim::SimRecording::kDepthboard, spec).raw_depth;
  const cv::Mat mm = mm_sim.Render(sim::SimRecording::kDepthboard, spec).raw_depth;
  const sim::DepthFormation& f = mm_sim.scenario().depth;
  int readings = 0;
  for (int v = 0; v < raw.rows; v += 4) {
    for (int u = 0; u < raw.cols; u += 4) {
      const std::uint16_t r = raw.at<std::uint16_t>(v, u), m = mm.at<std::uint16_t>(v, u);
      if (r == 2047) {
        ASSERT_EQ(m, 0) << "at " << u << "," << v;
        continue;
      }
      ++readings;
      ASSERT_EQ(m, std::round(1000 * (f.DepthFromRaw(r) - 0.01) / 1.02)) << "at " << u << "," << v;
    }
  }
  EXPECT_GT(readings, 5000);
}

TEST(ModelSpecUnits, MillimetresTakeTheLinearForm) {
  EXPECT_EQ(DefaultModelSpec(DepthUnits::kMillimetre).base_form, model::BaseForm::kLinearMm);
  EXPECT_EQ(DefaultModelSpec(DepthUnits::kRaw11Bit).base_form, model::BaseForm::kReciprocal);
  EXPECT_THROW(CheckModelUnits(DefaultModelSpec(DepthUnits::kRaw11Bit), DepthUnits::kMillimetre, "m.json"), InputError);
  EXPECT_THROW(CheckModelUnits(DefaultModelSpec(DepthUnits::kMillimetre), DepthUnits::kRaw11Bit, "m.json"), InputError);
  EXPECT_NO_THROW(CheckModelUnits(DefaultModelSpec(DepthUnits::kMillimetre), DepthUnits::kMillimetre, "m.json"));
  // A millimetre-only effect on a raw session is refused, naming the effect.
  ModelSpec raw = DefaultModelSpec(DepthUnits::kRaw11Bit);
  raw.effects.push_back(model::EffectSpecFromJson("thermal_drift_mm", "--add-effect"));
  try {
    CheckModelUnits(raw, DepthUnits::kRaw11Bit, "--add-effect");
    ADD_FAILURE() << "thermal_drift_mm accepted on a raw session";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("thermal_drift_mm is for millimetre sessions"), std::string::npos) << e.what();
  }
  ModelSpec mm = DefaultModelSpec(DepthUnits::kMillimetre);
  mm.effects = raw.effects;
  EXPECT_NO_THROW(CheckModelUnits(mm, DepthUnits::kMillimetre, "m.json"));
}

TEST(StampPairing, NearestWithinTheGapClosestFirst) {
  const std::int64_t ms = 1000000;
  // Depth at 0, 33, 66 ms; colour at 5, 30, 200 ms: 33 takes 30 (3 ms) before
  // 0 could; 0 takes 5; 66 has nothing within 20 ms; 200 stays alone.
  const auto pairs = PairByStamp({0, 33 * ms, 66 * ms}, {5 * ms, 30 * ms, 200 * ms}, 20 * ms);
  ASSERT_EQ(pairs.size(), 4u);
  EXPECT_EQ(pairs[0].depth, 0);
  EXPECT_EQ(pairs[0].colour, 0);
  EXPECT_EQ(pairs[1].depth, 1);
  EXPECT_EQ(pairs[1].colour, 1);
  EXPECT_EQ(pairs[2].depth, 2);
  EXPECT_EQ(pairs[2].colour, -1);
  EXPECT_EQ(pairs[3].depth, -1);
  EXPECT_EQ(pairs[3].colour, 2);
  // Two depth frames wanting one colour frame: the closer wins.
  const auto contested = PairByStamp({0, 10 * ms}, {8 * ms}, 20 * ms);
  EXPECT_EQ(contested[0].colour, -1);
  EXPECT_EQ(contested[1].colour, 0);
}

TEST(DepthUnitsDetection, FollowsTheDriversConventions) {
  std::string why;
  EXPECT_EQ(DetectDepthUnits(4000, 100, 0, &why), DepthUnits::kMillimetre);
  EXPECT_EQ(DetectDepthUnits(2047, 0, 5000, &why), DepthUnits::kRaw11Bit);
  EXPECT_NE(why.find("2047"), std::string::npos);
  EXPECT_EQ(DetectDepthUnits(1800, 300, 0, &why), DepthUnits::kMillimetre);
  EXPECT_EQ(DetectDepthUnits(2047, 10, 5000, &why), DepthUnits::kMillimetre);  // 0 marks none: REP 118
  // A fully lit raw scene has neither mark: it is not taken for millimetres.
  EXPECT_EQ(DetectDepthUnits(1090, 0, 0, &why), std::nullopt);
  EXPECT_NE(why.find("no pixel is 0"), std::string::npos);
}

}  // namespace
}  // namespace speckle
