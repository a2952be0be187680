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

}  // namespace
}  // namespace speckle
