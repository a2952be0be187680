// The writers' and readers' plausibility check (apply/plausibility.h) on a
// whole simulated session, as a user meets it: a wrong board description
// ends the run, is kept flagged, and is passed by; --accept-implausible keeps
// it. Slow tier: it records and calibrates sessions (20 s); the fast tier
// keeps plausibility_test's unit checks.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "apply/plausibility.h"
#include "schemas/errors.h"
#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;
using nlohmann::json;

// Issue 47: a square size typed 3/4 of the board's gave a normal summary,
// every depth 25 % short, and the newest version. Now the run ends with exit
// 3 naming the likely cause, the version is kept for inspection but passed
// by as the newest, refit and apply-calibration refuse it, and
// --accept-implausible keeps it for a sensor outside the family.
TEST(PipelinePlausibility, AWrongSquareSizeIsFlaggedAndNotTheNewest) {
  using namespace testing;
  ScratchDir s;
  fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", s / "s", fs::copy_options::recursive);
  const std::string session = (s / "s").string();
  ASSERT_EQ(RunTool("run-pipeline", session).exit_code, 0);
  EXPECT_EQ(ReadJson(s / "s" / "calibrations" / "v0001" / "calibration.json")["plausibility"]["problems"],
            json::array());
  // The board's size by the depth's own triangulation agrees with the rig's.
  const json size =
      ReadJson(s / "s" / "calibrations" / "v0001" / "report.json")["depthboard_quads"]["board_size_in_depth"];
  ASSERT_TRUE(size.is_object()) << size;
  EXPECT_NEAR(size["ratio"].get<double>(), 1.0, 0.05) << size;
  EXPECT_FALSE(size["outside_family"].get<bool>()) << size;
  json manifest = ReadJson(s / "s" / "session.json");
  manifest["rig"]["square_size_m"] = 0.75 * manifest["rig"]["square_size_m"].get<double>();
  std::ofstream(s / "s" / "session.json") << manifest.dump(2);
  const auto flagged = RunTool("run-pipeline", session);
  EXPECT_EQ(flagged.exit_code, kExitBadInput) << flagged.output;
  for (const std::string text :
       {"v0002 is not a calibration a Kinect v1 / PrimeSense sensor gives", "every depth is likely about 2", "% short",
        "square_size_m is one square's side in metres", "--accept-implausible",
        // said before any fit, from the depth alone
        "the depth sensor measures the board 3", "% larger than", "Most likely rig.square_size_m is wrong"})
    EXPECT_NE(flagged.output.find(text), std::string::npos) << text << "\n" << flagged.output;
  const json v2 = ReadJson(s / "s" / "calibrations" / "v0002" / "calibration.json");
  EXPECT_EQ(v2["plausibility"]["problems"].size(), 1u) << v2["plausibility"];
  EXPECT_FALSE(v2["plausibility"]["accepted"]);
  // The newest plausible version is used, and the one passed by is named.
  const auto applied =
      RunTool("apply-calibration", session + " --recording planar --frames 0:1 --out " + (s / "applied").string());
  EXPECT_EQ(applied.exit_code, 0) << applied.output;
  EXPECT_NE(applied.output.find("v0002: passed by"), std::string::npos) << applied.output;
  EXPECT_NE(ReadJson(s / "applied" / "applied.json").dump().find("v0001"), std::string::npos);
  const auto named = RunTool("apply-calibration", "--calibration " + (s / "s" / "calibrations" / "v0002").string() +
                                                      " --out " + (s / "named").string());
  EXPECT_EQ(named.exit_code, kExitBadInput) << named.output;
  EXPECT_NE(named.output.find("so it is not used"), std::string::npos) << named.output;
  const auto refit = RunTool("refit", session + " --from v0002");
  EXPECT_EQ(refit.exit_code, kExitBadInput) << refit.output;
  EXPECT_NE(refit.output.find("nothing to refit from"), std::string::npos) << refit.output;
  EXPECT_FALSE(fs::exists(s / "s" / "calibrations" / "v0003"));
  // Accepted: a calibration like any other, that says what was accepted.
  const auto accepted = RunTool("run-pipeline", session + " --accept-implausible");
  EXPECT_EQ(accepted.exit_code, 0) << accepted.output;
  EXPECT_NE(accepted.output.find("kept with --accept-implausible"), std::string::npos) << accepted.output;
  EXPECT_TRUE(ReadJson(s / "s" / "calibrations" / "v0003" / "calibration.json")["plausibility"]["accepted"]);
  const auto refit_accepted = RunTool("refit", session);
  EXPECT_EQ(refit_accepted.exit_code, 0) << "the parent's acceptance carries on: " << refit_accepted.output;
}

}  // namespace
}  // namespace speckle
