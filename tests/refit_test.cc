// refit states what a new model costs beside what it gains (issue 47): the
// depth sigma as run-pipeline prints it, against the parent's, and the camera
// warnings still in force.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;
using nlohmann::json;

TEST(RefitCosts, TheDepthSigmaIsComparedWithTheParentsAndCameraWarningsRepeated) {
  ScratchDir s;
  fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", s / "s", fs::copy_options::recursive);
  const std::string session = (s / "s").string();
  ASSERT_EQ(RunTool("run-pipeline", session).exit_code, 0);
  const auto same = RunTool("refit", session + " --from v0001");
  ASSERT_EQ(same.exit_code, 0) << same.output;
  EXPECT_NE(same.output.find("depth sigma  ± "), std::string::npos) << same.output;
  EXPECT_NE(same.output.find("against v0001: within 20 % of its sigma at every depth"), std::string::npos)
      << same.output;
  // A parent known twice as well: the refit's sigma is then twice its, said
  // with where it grows most.
  const fs::path v1 = s / "s" / "calibrations" / "v0001";
  json report = ReadJson(v1 / "report.json");
  ASSERT_FALSE(report["depth_uncertainty"].empty());
  for (auto& row : report["depth_uncertainty"]) row["sigma_mm"] = 0.5 * row["sigma_mm"].get<double>();
  std::ofstream(v1 / "report.json") << report.dump();
  json calibration = ReadJson(v1 / "calibration.json");
  calibration["cameras"]["depth_intrinsics_warning"] = "the depth camera is known only loosely (test)";
  std::ofstream(v1 / "calibration.json") << calibration.dump();
  const auto grown = RunTool("refit", session + " --from v0001");
  ASSERT_EQ(grown.exit_code, 0) << grown.output;
  EXPECT_NE(grown.output.find("against v0001: the sigma grows, most at "), std::string::npos) << grown.output;
  EXPECT_NE(grown.output.find("(+100 %)"), std::string::npos) << grown.output;
  EXPECT_NE(grown.output.find("warning      the depth camera is known only loosely (test)"), std::string::npos)
      << grown.output;
}

// A formula term that never applies and two that move the raw value alike:
// refit names them as not identified, and calibration.json holds no sigma for
// them (the first had sigma 0, printed "held, not fitted"; the two a split of
// their sum's).
TEST(RefitCosts, ParametersTheSamplesDoNotDetermineHaveNoSigma) {
  ScratchDir s;
  const fs::path session = CalibratedGoldenSession(s.path()).parent_path().parent_path();
  const nlohmann::json odd = {
      {"schema_version", 2},
      {"base_form", "reciprocal"},
      {"effects",
       {{{"name", "never"}, {"formula", "p * (raw > 5000)"}, {"parameters", {{{"name", "p"}, {"unit", "raw"}}}}},
        {{"name", "twins"},
         {"formula", "q1 * x + q2 * x"},
         {"parameters", {{{"name", "q1"}, {"unit", "raw"}}, {{"name", "q2"}, {"unit", "raw"}}}}}}}};
  std::ofstream(s / "odd.json") << odd.dump();
  const auto refit = RunTool("refit", session.string() + " --model " + (s / "odd.json").string());
  ASSERT_EQ(refit.exit_code, 0) << refit.output;
  EXPECT_NE(refit.output.find("not identified: never.p, twins.q1, twins.q2"), std::string::npos) << refit.output;
  EXPECT_EQ(refit.output.find("held, not fitted"), std::string::npos) << refit.output;
  const json calibration = ReadJson(session / "calibrations" / "v0002" / "calibration.json");
  int unidentified = 0;
  for (const auto& p : calibration["model"]["parameters"]) {
    const bool identified = p["identified"];
    EXPECT_EQ(p["sigma"].is_null(), !identified) << p.dump();
    if (identified) EXPECT_GT(p["sigma"].get<double>(), 0) << p.dump();
    unidentified += !identified;
  }
  EXPECT_EQ(unidentified, 3);
}

}  // namespace
}  // namespace speckle
