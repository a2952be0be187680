// The plain result line (issue 47): good, limited by what, or not usable,
// from the version's calibration.json and report.json as they are written.
#include "pipeline/assessment.h"

#include <gtest/gtest.h>

namespace speckle {
namespace {

// A report and calibration as run-pipeline writes them, cut to what the
// assessment reads: a stock rig, the diagnosis at `ratio` times its floor.
struct Version {
  nlohmann::json report, calibration;
};

Version Written(double ratio) {
  Version v;
  const bool complete = ratio <= 1.15;  // the diagnosis's complete_ratio
  v.report = {{"diagnosis",
               {{"ratio_to_floor", ratio},
                {"complete", complete},
                {"conclusion", complete ? "complete" : "outside_catalogue"},
                {"recommended", nullptr}}},
              {"frames", nlohmann::json::array()}};
  const nlohmann::json camera = {{"fx", 585.0},
                                 {"fy", 585.0},
                                 {"cx", 320.0},
                                 {"cy", 240.0},
                                 {"image_size", {640, 480}},
                                 {"rms_reprojection_px", 0.2}};
  v.calibration = {{"cameras",
                    {{"colour", camera},
                     {"depth", camera},
                     {"depth_intrinsics_warning", nullptr},
                     {"depth_from_colour", {{"translation_m", {0.025, 0, 0}}}}}},
                   {"model", {{"base_form", "reciprocal"}, {"parameters", nlohmann::json::array()}}},
                   {"plausibility", {{"problems", nlohmann::json::array()}, {"accepted", false}}}};
  return v;
}

TEST(Assessment, AtTheFloorWithNoWarningIsGoodAndCarriesTheCamerasAndWarnings) {
  Version v = Written(1.02);
  AddAssessment(v.report, v.calibration, {"a warning the run logged"});
  EXPECT_EQ(v.report["assessment"]["status"], "good");
  EXPECT_EQ(AssessmentLine(v.report), "result       good: held out 1.02x the noise floor, no camera warning\n");
  EXPECT_EQ(v.report["cameras"], v.calibration["cameras"]);
  EXPECT_EQ(v.report["warnings"], nlohmann::json({"a warning the run logged"}));
}

TEST(Assessment, AMissingEffectALooseDepthCameraAndRejectedWallsEachLimitIt) {
  Version v = Written(2.4);
  v.report["diagnosis"]["recommended"] = "thermal_drift";
  v.calibration["cameras"]["depth_intrinsics_warning"] = "the depth camera is known only loosely";
  for (int i = 0; i < 4; ++i)
    v.report["frames"].push_back({{"recording", "planar"}, {"reason", i < 3 ? nlohmann::json("tilted") : nullptr}});
  AddAssessment(v.report, v.calibration, {});
  EXPECT_EQ(v.report["assessment"]["status"], "limited");
  const std::string line = AssessmentLine(v.report);
  EXPECT_NE(line.find("held out 2.40x the noise floor; the verdict adds thermal_drift"), std::string::npos) << line;
  EXPECT_NE(line.find("the depth camera's intrinsics"), std::string::npos) << line;
  EXPECT_NE(line.find("the wall snapshots"), std::string::npos) << line;
  // The camera's warning and the walls' are in the page's warnings though no logger said them.
  EXPECT_EQ(v.report["warnings"].size(), 2u) << v.report["warnings"].dump();
}

TEST(Assessment, ARigNoKinectGivesIsNotUsableUnlessAccepted) {
  Version v = Written(1.0);
  v.calibration["cameras"]["depth"]["fx"] = 1685119.0;  // --squares 8x6 on a 9x7 board (issue 47's trial)
  v.calibration["plausibility"]["problems"] = {"the depth camera's fx"};
  AddAssessment(v.report, v.calibration, {});
  EXPECT_EQ(v.report["assessment"]["status"], "not usable");
  EXPECT_NE(AssessmentLine(v.report).find("not usable: not a calibration a Kinect v1"), std::string::npos);
  v.calibration["plausibility"]["accepted"] = true;
  AddAssessment(v.report, v.calibration, {});
  EXPECT_EQ(v.report["assessment"]["status"], "limited");
  EXPECT_NE(AssessmentLine(v.report).find("--accept-implausible"), std::string::npos);
}

// No noise floor (ratio 0) is not "good: held out 0.00x the floor"; a
// damaged frame entry in a parent's report is passed over, not a crash.
TEST(Assessment, WithoutANoiseFloorItIsNotAssessedAndDamagedFramesAreSkipped) {
  Version v = Written(0);
  v.report["frames"] = {42, "x", {{"recording", 7}}};
  AddAssessment(v.report, v.calibration, {});
  EXPECT_EQ(v.report["assessment"]["status"], "not assessed");
}

}  // namespace
}  // namespace speckle
