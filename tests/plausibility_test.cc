// The writers' and readers' plausibility check (apply/plausibility.h) on a
// calibration's numbers; on whole sessions, plausibility_session_test.cc.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "apply/plausibility.h"

namespace speckle {
namespace {

using nlohmann::json;

// The likely cause follows the fit's own sigma: a camera its views leave
// loose is too few or too alike poses before it is a wrong board (issue 47's
// outside probe: 12 poses of a board described right, fy -319899.6 +-
// 1551262, were sent to check the board).
TEST(PipelinePlausibility, ALooseCameraIsBlamedOnThePosesAndAPreciseOneOnTheBoard) {
  const auto calibration = [](double sigma_fy) {
    json depth = {{"fx", 580.0}, {"fy", -319899.6},           {"cx", 320.0}, {"cy", 240.0}, {"image_size", {640, 480}},
                  {"views", 12}, {"rms_reprojection_px", 0.3}};
    depth["stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3"] = {2.0, sigma_fy, 1.0, 1.0, 0, 0, 0, 0, 0};
    return json{{"cameras", {{"depth", depth}}}};
  };
  const std::string loose = apply::JoinProblems(apply::ImplausibleCalibration(calibration(1551262)));
  EXPECT_NE(loose.find("known only to ± 1551262 px"), std::string::npos) << loose;
  EXPECT_NE(loose.find("Most likely the board poses do not pin the camera down"), std::string::npos) << loose;
  const std::string precise = apply::JoinProblems(apply::ImplausibleCalibration(calibration(40)));
  EXPECT_EQ(precise.find("known only to"), std::string::npos) << precise;
  EXPECT_NE(precise.find("Most likely the board is described wrongly"), std::string::npos) << precise;
}

}  // namespace
}  // namespace speckle
