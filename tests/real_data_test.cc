// Real Kinect data through the whole tool with no manual step: Herrera's
// toolbox sample set (board larger than its chessboard, so board-plane
// pairing with the joint Ceres fit). The outcome is pinned so a regression
// shows: the fitted reciprocal model, the depth intrinsics, the residual.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;
using nlohmann::json;

// Herrera's set as the README imports it, into `session`.
void ImportHerrera(const std::filesystem::path& session) {
  const auto imported = RunTool(
      "record-session", "frames:" + (SharedData() / "herrera_kinect_calib").string() +
                            " --squares 9x7 --square-size 0.04 --outline larger_board --out " + session.string());
  ASSERT_EQ(imported.exit_code, 0) << imported.output;
}

// The separate steps (--separate-cameras) on Herrera's set, pinned; the
// joint calibration, the default, is HerrerasDepthCameraIsPinnedByTheJointFit... below.
TEST(RealData, HerreraSampleSetCalibratesUnderTwoRawUnits) {
  ScratchDir s;
  ASSERT_NO_FATAL_FAILURE(ImportHerrera(s / "h"));
  const auto r = RunTool("run-pipeline", (s / "h").string() + " --separate-cameras");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(s / "h" / "calibrations" / "v0001" / "calibration.json");
  const json c = json::parse(in);
  EXPECT_GE(c["metrics"]["paired_frames"].get<int>(), 30) << "38 frames have colour and depth";
  // The 15 chessboard views with colour alone calibrate the colour camera:
  // said so, and not counted rejected (they were, for having no depth).
  EXPECT_NE(r.output.find("colour only  15 board frame(s) without depth"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("rejected     15 frame(s)"), std::string::npos) << r.output;
  // ...nor in the paired share, which was 39 of 54.
  EXPECT_EQ(c["metrics"]["colour_view_frames"], 15);
  EXPECT_GE(c["metrics"]["paired_share"].get<double>(), 0.95) << c["metrics"];
  EXPECT_NE(r.output.find("39 of 39 depthboard frames with depth paired"), std::string::npos) << r.output;
  const json first = ReadJson(s / "h" / "calibrations" / "v0001" / "report.json");
  for (const auto& rejection : first["rejections"])
    EXPECT_EQ(rejection["reason"].get<std::string>().find("no depth image"), std::string::npos) << rejection.dump();
  EXPECT_EQ(c["model"]["base_form"], "reciprocal");
  EXPECT_EQ(c["cameras"]["depth_intrinsics_source"], "joint_board_planes");
  // Pinned (2026-11-22, the model with the undistortion grid from the walls'
  // own planes); ranges allow numerical noise only.
  const json& p = c["model"]["parameters"];
  EXPECT_NEAR(p[0]["value"].get<double>(), -0.0028426, 0.00003);
  EXPECT_NEAR(p[1]["value"].get<double>(), 3.1094, 0.03);
  const json& depth = c["cameras"]["depth"];
  EXPECT_NEAR(depth["fx"].get<double>(), 576.6, 3);
  EXPECT_NEAR(depth["fy"].get<double>(), 577.5, 3);
  EXPECT_NEAR(depth["cx"].get<double>(), 331.9, 3);
  EXPECT_NEAR(depth["cy"].get<double>(), 229.9, 3);
  EXPECT_LT(c["metrics"]["held_out_raw"]["rms"].get<double>(), 2.0) << "the issue's target";
  EXPECT_LT(c["metrics"]["held_out_mm"]["rms"].get<double>(), 7.0);
  // The set's walls are up to 2.3 degrees off square: taken as their own
  // planes, they give an undistortion grid that flattens held-out walls and
  // lowers the boards' held-out error (1.889 -> 1.320 raw when measured).
  EXPECT_EQ(c["model"]["undistortion"], true);
  const json auto_report = ReadJson(s / "h" / "calibrations" / "v0001" / "report.json");
  EXPECT_EQ(auto_report["undistortion"]["true_raw_method"], "own_plane");
  EXPECT_GT(auto_report["undistortion"]["wall_sigma_reduction_held_out"].get<double>(), 0.4);
  // Frames 38-53 are depth-only views of a flat wall filling the image: the
  // wall segmentation keeps every one, as the wall it is, and no frame of
  // the set is rejected as a planar snapshot.
  EXPECT_EQ(auto_report["planar_snapshots"].size(), 16u) << auto_report["rejections"];
  for (const auto& snapshot : auto_report["planar_snapshots"])
    EXPECT_GT(snapshot["wall_share"].get<double>(), 0.5) << snapshot["frame"];
  // With the plain reciprocal model (no grid), the diagnosis finds the spatial
  // structure real Kinects have and names the effect that explains it; held
  // out by pose, adding it lowers the error.
  const auto plain = RunTool("run-pipeline", (s / "h").string() + " --separate-cameras --model " + SPECKLE_SOURCE_DIR +
                                                 "/examples/hunt/plain_reciprocal_model.json");
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  const json report = ReadJson(s / "h" / "calibrations" / "v0002" / "report.json");
  const auto& d = report["diagnosis"];
  // A spatial effect: the per-pixel pattern decaying with disparity, or the
  // smooth scale-and-offset field (they rank within a few per cent here).
  const std::string recommended = d["recommended"].is_string() ? d["recommended"].get<std::string>() : "";
  EXPECT_TRUE(recommended == "disparity_pattern" || recommended == "spatial_field") << d["verdict"];
  const std::string top = d["covariates"][0]["covariate"];
  EXPECT_NE(top.find("image"), std::string::npos) << d["verdict"];
  EXPECT_LT(d["candidates"][0]["held_out_raw"].get<double>(), 0.8 * d["held_out_raw"].get<double>());
  // The verdict's refit (issue 47's trial): it states what it costs. The
  // sigma grows, and where no pose reached (the image's edges) the depth
  // moves beyond it, which is said and limits the result.
  const auto refit = RunTool("refit", (s / "h").string() + " --from v0001 --add-effect disparity_pattern");
  ASSERT_EQ(refit.exit_code, 0) << refit.output;
  for (const std::string text : {"against v0001: the sigma grows", "warning      where no board pose reached",
                                 "the model is extrapolated there", "result       limited by"})
    EXPECT_NE(refit.output.find(text), std::string::npos) << text << "\n" << refit.output;
  const json refit_report = ReadJson(s / "h" / "calibrations" / "v0003" / "report.json");
  EXPECT_TRUE(refit_report["unseen_regions"]["beyond_sigma"].get<bool>()) << refit_report["unseen_regions"];
  EXPECT_GT(refit_report["unseen_regions"]["unseen_share"].get<double>(), 0.1);
}

// The joint calibration on Herrera's set, whose board is larger than its
// chessboard (no outline): the board planes' depth samples pin the depth
// camera inside the bundle adjustment, as Herrera's toolbox does. Measured
// (2026-12-03): fx 579.0 +- 1.8, fy 580.8 +- 1.4, cx 328.7 +- 1.7, cy 231.0
// +- 1.9 px against the board planes' own fx 578.9 +- 27.1; the toolbox's
// fx 579.83; held out 0.965 raw against 1.325 without it.
TEST(RealData, HerrerasDepthCameraIsPinnedByTheJointFitWithoutOutlines) {
  ScratchDir s;
  ASSERT_NO_FATAL_FAILURE(ImportHerrera(s / "h"));
  const auto r = RunTool("run-pipeline", (s / "h").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json c = ReadJson(s / "h" / "calibrations" / "v0001" / "calibration.json");
  const json& joint = c["cameras"]["joint"];
  ASSERT_TRUE(joint.is_object()) << c["cameras"];
  EXPECT_EQ(joint["terms"][1]["observations"].get<int>(), 0) << joint;  // no outline corners
  EXPECT_GT(joint["terms"][2]["observations"].get<int>(), 1000) << joint;
  const json& depth = c["cameras"]["depth"];
  EXPECT_NEAR(depth["fx"].get<double>(), 579.83, 0.01 * 579.83) << depth;
  for (int i = 0; i < 4; ++i)
    EXPECT_LT(depth["stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3"][i].get<double>(), 0.01 * depth["fx"].get<double>())
        << i << " " << depth;
  // The board planes' own fit warned (fx +- 27.1 px); the joint camera is judged anew, and is not loose.
  EXPECT_EQ(r.output.find("warning      the depth camera is known only loosely"), std::string::npos) << r.output;
  EXPECT_TRUE(c["cameras"]["depth_intrinsics_warning"].is_null()) << c["cameras"];
  EXPECT_TRUE(joint["terms"][1]["rms"].is_null()) << joint;  // no scatter of observations there are none of
  EXPECT_LT(c["metrics"]["held_out_raw"]["rms"].get<double>(), 1.1);
  // The refit the verdict recommends fits the cameras with the field (it kept
  // v0001's when the field's priors were left out of the joint covariance),
  // and says which camera terms the field trades with: without outlines its
  // planes and the principal point are one signature (cx +- 6.0 px, 0.9 with
  // the field known; held out 0.803 raw, 0.845 with the cameras kept).
  ASSERT_NE(r.output.find("--add-effect spatial_field"), std::string::npos) << r.output;
  const auto refit = RunTool("refit", (s / "h").string() + " --add-effect spatial_field");
  ASSERT_EQ(refit.exit_code, 0) << refit.output;
  EXPECT_EQ(refit.output.find("joint calibration not fitted"), std::string::npos) << refit.output;
  EXPECT_NE(refit.output.find("(39 views; "), std::string::npos) << refit.output;
  EXPECT_NE(refit.output.find("depth cx ± "), std::string::npos) << refit.output;
  EXPECT_NE(refit.output.find("with spatial_field's parameters known"), std::string::npos) << refit.output;
  const json after = ReadJson(s / "h" / "calibrations" / "v0002" / "calibration.json");
  EXPECT_LT(after["metrics"]["held_out_raw"]["rms"].get<double>(), 0.83);
}

// Xiang's small set with the separate steps (--separate-cameras): 16 poses and
// no IR images, so the depth camera, the rig
// and the depth model come from the joint board-plane fit alone, and every
// uncertainty the calibration states must come from it too. A new user found
// "the extrinsics' depth offset to ± 0.0 mm", translation_sigma_m [0, 0, 0]
// and outline_rms_px 0.0 (no outlines were fitted) there.
TEST(RealData, XiangSmallSetStatesTheJointFitsUncertainty) {
  ScratchDir s;
  const auto imported = RunTool(
      "record-session", "frames:" + (SharedData() / "xiang_kinect_smallset/smallset").string() +
                            " --squares 11x8 --square-size 0.031 --outline larger_board --out " + (s / "x").string());
  ASSERT_EQ(imported.exit_code, 0) << imported.output;
  const auto r = RunTool("run-pipeline", (s / "x").string() + " --separate-cameras");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json c = ReadJson(s / "x" / "calibrations" / "v0001" / "calibration.json");
  EXPECT_EQ(c["cameras"]["depth_intrinsics_source"], "joint_board_planes");
  const json& rig = c["cameras"]["depth_from_colour"];
  EXPECT_TRUE(rig["outline_rms_px"].is_null()) << rig;
  EXPECT_TRUE(c["cameras"]["depth"]["rms_reprojection_px"].is_null()) << c["cameras"]["depth"];
  ASSERT_TRUE(rig["translation_sigma_m"].is_array()) << rig;
  for (const auto& sigma : rig["translation_sigma_m"]) {
    // Measured 32, 12 and 17 mm: 16 poses pin the rig loosely.
    EXPECT_GT(sigma.get<double>(), 0.001) << rig;
    EXPECT_LT(sigma.get<double>(), 0.1) << rig;
  }
  EXPECT_EQ(r.output.find("± 0.0 mm"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("0.000 ± 0.000"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("lens not fitted"), std::string::npos) << r.output;
  // The joint fit's uncertainty widens the depth model's parameters (its
  // refits moved with the camera), but not the noise floor: the cameras were
  // fitted to these very residuals. Measured b ± 0.1 1/m with it, ± 0.0093
  // without; the floor 0.539 raw either way.
  EXPECT_GT(c["model"]["parameters"][1]["sigma_from_cameras"].get<double>(), 0.02) << c["model"]["parameters"][1];
  EXPECT_LT(c["metrics"]["noise_floor_raw"].get<double>(), 0.8);
  // A refit keeps it: the perturbations and which of them count in the
  // floor come from samples.h5.
  const auto refit = RunTool("refit", (s / "x").string() + " --add-effect depth_grid_offset");
  ASSERT_EQ(refit.exit_code, 0) << refit.output;
  const json c2 = ReadJson(s / "x" / "calibrations" / "v0002" / "calibration.json");
  EXPECT_NEAR(c2["metrics"]["noise_floor_raw"].get<double>(), c["metrics"]["noise_floor_raw"].get<double>(), 0.05);
  EXPECT_EQ(c2["cameras"]["depth_from_colour"]["translation_sigma_m"], rig["translation_sigma_m"]);
}

// Xiang's set keeps 5 wall views among its boards (0016-0020) and 10 more
// in wall/: --add-to takes the second folder as planar-2.h5 (it refused a
// second planar recording), and run-pipeline reads every wall.
TEST(RealData, XiangsWallFolderIsAddedToItsSessionAndEveryWallIsRead) {
  ScratchDir s;
  const auto imported = RunTool(
      "record-session", "frames:" + (SharedData() / "xiang_kinect_smallset/smallset").string() +
                            " --squares 11x8 --square-size 0.031 --outline larger_board --out " + (s / "x").string());
  ASSERT_EQ(imported.exit_code, 0) << imported.output;
  const auto added = RunTool("record-session", "frames:" + (SharedData() / "xiang_kinect_smallset/wall").string() +
                                                   " --add-to " + (s / "x").string());
  ASSERT_EQ(added.exit_code, 0) << added.output;
  EXPECT_NE(added.output.find("planar-2.h5: 10 frames (planar)"), std::string::npos) << added.output;
  const json session = ReadJson(s / "x" / "session.json");
  int planar = 0;
  for (const auto& r : session["recordings"]) planar += r["purpose"] == "planar";
  EXPECT_EQ(planar, 2) << session["recordings"];
  EXPECT_EQ(RunTool("session-info", (s / "x").string()).exit_code, 0);
  // The same folder again would count every wall twice: refused by name.
  const auto again = RunTool("record-session", "frames:" + (SharedData() / "xiang_kinect_smallset/wall").string() +
                                                   " --add-to " + (s / "x").string());
  EXPECT_EQ(again.exit_code, 3) << again.output;
  EXPECT_NE(again.output.find("the session already holds this recording (planar-2.h5"), std::string::npos)
      << again.output;
  const auto r = RunTool("run-pipeline", (s / "x").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("15 of 15 planar (wall) frames kept"), std::string::npos) << r.output;
  // The second recording's frames are numbered on from the first's.
  const json report = ReadJson(s / "x" / "calibrations" / "v0001" / "report.json");
  std::set<int> frames;
  for (const auto& snapshot : report["planar_snapshots"]) frames.insert(snapshot["frame"].get<int>());
  EXPECT_EQ(frames.size(), 15u);
  EXPECT_EQ(*frames.rbegin(), 14);
}

}  // namespace
}  // namespace speckle
