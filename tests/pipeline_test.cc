// run-pipeline end to end on simulated sessions, as a user runs it: the stock
// depth model is recovered within its reported uncertainty, artifacts are
// versioned and never overwritten, and unusable input is explained.
#include <gtest/gtest.h>

#include <cmath>
#include <regex>

#include <H5Cpp.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "apply/undistortion_grid_file.h"
#include "lab/diagnosis/verdict_text.h"
#include "pipeline/samples_file.h"
#include "pipeline/sha256_file.h"
#include "schemas/artifact_schema.h"
#include "schemas/errors.h"
#include "simulator/scenario.h"
#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;
using nlohmann::json;

// One simulated stock session shared by the tests below (recording it is the
// slow part): ctest records it once (fixture stock_session_recorded) and each
// test copies it; the binary run on its own records it.
class StockSession : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scratch_ = new ScratchDir();
    const fs::path recorded = fs::path(SPECKLE_BIN_DIR) / "test-sessions" / "stock";
    if (fs::exists(recorded / "session.json")) {
      fs::copy(recorded, scratch_->path() / "s", fs::copy_options::recursive);
      return;
    }
    const auto r = RunTool("record-session", "sim --out " + (scratch_->path() / "s").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  static void TearDownTestSuite() { delete scratch_; }
  static fs::path Session() { return scratch_->path() / "s"; }
  static ScratchDir* scratch_;
};
ScratchDir* StockSession::scratch_ = nullptr;

// The seconds after `what` in the summary's last line, "time ... s: ..."
// (NaN when it is not there).
double SecondsOf(const std::string& output, const std::string& what) {
  std::smatch line, m;
  if (!std::regex_search(output, line, std::regex("(^|\n)time [^\n]*"))) return std::nan("");
  const std::string text = line[0];
  return std::regex_search(text, m, std::regex(what + " ([0-9]+\\.[0-9]) s")) ? std::stod(m[1]) : std::nan("");
}

TEST_F(StockSession, RecoversTheTrueReciprocalModelWithinItsReportedUncertainty) {
  const auto r = RunTool("run-pipeline", Session().string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The time line's parts add up within the total: the comparison fits run
  // beside the diagnosis, and the line counts them once (each part rounded
  // to 0.1 s).
  const double total = SecondsOf(r.output, "time +"), diagnosis = SecondsOf(r.output, "then diagnosis");
  const double parts =
      SecondsOf(r.output, "graph") + SecondsOf(r.output, "cameras") + SecondsOf(r.output, "[0-9]+ fits") +
      std::max(diagnosis, SecondsOf(r.output, "comparison fits")) + SecondsOf(r.output, "wall hold-outs");
  ASSERT_FALSE(std::isnan(parts)) << r.output;
  EXPECT_LE(parts, total + 0.3) << r.output;
  const json calibration = ReadJson(Session() / "calibrations" / "v0001" / "calibration.json");
  EXPECT_EQ(calibration["schema"], "speckle.calibration");
  EXPECT_EQ(calibration["schema_version"], kCalibrationSchemaVersion);
  const json& metrics = calibration["metrics"];
  EXPECT_GE(metrics["paired_share"].get<double>(), 0.95);
  EXPECT_EQ(calibration["model"]["base_form"], "reciprocal");
  const sim::Scenario truth;  // the session was recorded with the defaults
  const double expected[] = {truth.depth.a, truth.depth.b};
  for (int i = 0; i < 2; ++i) {
    const json& p = calibration["model"]["parameters"][i];
    EXPECT_LT(std::abs(p["value"].get<double>() - expected[i]), 3 * p["sigma"].get<double>())
        << p["name"] << " = " << p["value"] << " ± " << p["sigma"] << ", truth " << expected[i];
  }
  // Residuals near the noise floor: the simulator's 0.6 raw noise plus
  // rounding, averaged by the 5x5 plane each raw value is read with, leaves
  // well under one raw unit.
  EXPECT_LT(metrics["held_out_raw"]["rms"].get<double>(), 0.8);
  // Within 15 % of the noise floor the data show (a board point's scatter over
  // the frames of a still pose: raw noise, rounding and the colour pose's noise).
  EXPECT_LE(metrics["held_out_to_floor"].get<double>(), 1.15);
  // The floor is at least the raw noise and rounding of one pixel,
  // sqrt(0.6^2 + 1/12) = 0.667 raw, averaged over the 5x5 window a board
  // point's raw value is read from (0.133 raw), and not far above it.
  EXPECT_GT(metrics["noise_floor_raw"].get<double>(), 0.133);
  EXPECT_LT(metrics["noise_floor_raw"].get<double>(), 0.3);
  for (const char* file : {"report.json", "samples.h5", "undistortion_grid.h5"}) {
    EXPECT_TRUE(fs::exists(Session() / "calibrations" / "v0001" / file)) << file;
  }
  // The grid reads back with the shape it was written with.
  const UndistortionGrid grid = ReadGrid(Session() / "calibrations" / "v0001" / "undistortion_grid.h5");
  EXPECT_EQ(grid.correction.size(), grid.raw_nodes.size() * grid.nx * grid.ny);
  // The cached samples read back whole.
  const CachedSamples cached = ReadSamples(Session() / "calibrations" / "v0001" / "samples.h5");
  EXPECT_EQ(cached.samples.size(), metrics["samples"].get<std::size_t>());
  // With every sample's depth under each camera input's one-sigma change.
  ASSERT_FALSE(cached.perturbations.empty());
  for (const auto& depths : cached.perturbations.depths) EXPECT_EQ(depths.size(), cached.samples.size());
}

TEST_F(StockSession, EveryRunIsANewVersionAndEarlierOnesAreUntouched) {
  const auto run = RunTool("run-pipeline", Session().string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const fs::path first = Session() / "calibrations" / "v0001" / "calibration.json";
  ASSERT_TRUE(fs::exists(first));
  const std::string before = Sha256File(first);
  const auto r =
      RunTool("run-pipeline", Session().string() + " --model " + (SharedData() / ".." / "nonexistent").string());
  EXPECT_EQ(r.exit_code, kExitBadInput) << "a missing model file is bad input\n" << r.output;
  EXPECT_NE(r.output.find("nonexistent: no such file"), std::string::npos) << r.output;
  const fs::path spec = Session() / "tangent.json";
  std::ofstream(spec) << R"({"base_form": "tangent", "undistortion": "off"})";
  const auto again = RunTool("run-pipeline", Session().string() + " --model " + spec.string());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(Sha256File(first), before);
  int versions = 0;
  for (const auto& e : fs::directory_iterator(Session() / "calibrations")) {
    EXPECT_EQ(e.path().filename().string()[0], 'v') << "no temporary directory may remain: " << e.path();
    ++versions;
  }
  EXPECT_GE(versions, 2);
  EXPECT_NE(again.output.find("tangent"), std::string::npos) << again.output;
}

TEST_F(StockSession, BadModelSpecIsNamed) {
  const fs::path spec = Session() / "bad.json";
  std::ofstream(spec) << R"({"base_form": "cubic"})";
  const auto r = RunTool("run-pipeline", Session().string() + " --model " + spec.string());
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.output.find("base_form"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace speckle

namespace speckle {
namespace {

TEST(PipelineSessionIntrinsics, GivenIntrinsicsAreUsedInsteadOfCalibrating) {
  using namespace testing;
  ScratchDir s;
  // The simulator's true stock cameras (thesis Appendix A), given as known.
  std::ofstream(s / "describe.json") << R"({"cameras": {
      "colour": {"image_size": [640, 480], "fx": 520.38, "fy": 520.19, "cx": 319.25, "cy": 261.87,
                 "distortion": [0.23026, -0.73952, 0.00085105, -0.0015311, 0.81742]},
      "depth": {"image_size": [640, 480], "fx": 588.92, "fy": 587.89, "cx": 315.10, "cy": 252.12,
                "distortion": [-0.089552, 0.47946, 0.0040476, 0.0045308, -0.80428]}}})";
  std::ofstream(s / "scenario.json")
      << R"({"depthboard": {"poses": 12, "frames_per_pose": 1}, "planar": {"snapshots": 0},
                                             "ir_chessboard": {"poses": 0}})";
  const auto recorded = RunTool("record-session", "sim --scenario " + (s / "scenario.json").string() + " --describe " +
                                                      (s / "describe.json").string() + " --out " + (s / "x").string());
  ASSERT_EQ(recorded.exit_code, 0) << recorded.output;
  EXPECT_EQ(ReadJson(s / "x" / "session.json")["schema_version"], 2);
  const auto r = RunTool("run-pipeline", (s / "x").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto c = ReadJson(s / "x" / "calibrations" / "v0001" / "calibration.json");
  EXPECT_EQ(c["cameras"]["depth_intrinsics_source"], "session");
  EXPECT_EQ(c["cameras"]["colour"]["fx"].get<double>(), 520.38);
  const auto& depth = c["cameras"]["depth"];
  EXPECT_EQ(depth["fx"].get<double>(), 588.92);
  // The depth camera given is the IR image's: the depth image's principal
  // point is fitted, here (no shift hidden) within 3 sigma of the given one.
  const auto& sigma = depth["stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3"];
  EXPECT_GT(sigma[2].get<double>(), 0);
  EXPECT_LT(std::abs(depth["cx"].get<double>() - 315.10), 3 * sigma[2].get<double>()) << depth;
  EXPECT_LT(std::abs(depth["cy"].get<double>() - 252.12), 3 * sigma[3].get<double>()) << depth;
  // With the true cameras the model lands within its reported uncertainty,
  // which then comes from the poses (grouped jackknife) and the extrinsics.
  const double truth[] = {-0.0027681, 3.0163};
  for (int i = 0; i < 2; ++i) {
    const auto& p = c["model"]["parameters"][i];
    EXPECT_LT(std::abs(p["value"].get<double>() - truth[i]), 3 * p["sigma"].get<double>()) << p;
  }
}

TEST(PipelineSessionIntrinsics, VersionOneSessionsStillRead) {
  using namespace testing;
  // The golden session was written with session schema version 1.
  EXPECT_EQ(ReadJson(fs::path(SPECKLE_SOURCE_DIR) / "tests/golden/session/session.json")["schema_version"], 1);
  EXPECT_EQ(RunTool("session-info", (fs::path(SPECKLE_SOURCE_DIR) / "tests/golden/session").string()).exit_code, 0);
}

}  // namespace
}  // namespace speckle

namespace speckle {
namespace {

TEST(ArtifactReaders, RejectForeignFilesAndUnknownVersions) {
  using namespace testing;
  ScratchDir s;
  // An HDF5 file that is a recording, not cached samples.
  const auto r = RunTool("record-session", "fakenect:" + (SharedData() / "fakenect_openiss_depth").string() +
                                               " --out " + (s / "x").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  try {
    ReadSamples(s / "x" / "free.h5");
    FAIL() << "a recording was read as samples";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("expected \"speckle.samples\""), std::string::npos) << e.what();
  }
  // Samples from a newer tool.
  WriteSamples(s / "samples.h5", {PairedSample{}}, {});
  {
    H5::H5File file((s / "samples.h5").string(), H5F_ACC_RDWR);
    const long long version = 99;
    file.openAttribute("schema_version").write(H5::PredType::NATIVE_LLONG, &version);
  }
  EXPECT_THROW(ReadSamples(s / "samples.h5"), SchemaVersionError);
  // More perturbations counted in the floor than there are (schema 5).
  fs::remove(s / "samples.h5");
  PairedSample sample;  // a reading and a depth (ReadSamples refuses a depth of 0)
  sample.raw = 700, sample.depth_m = 1.0;
  WriteSamples(s / "samples.h5", {sample}, DepthPerturbations{{{1.0}}, 1});
  {
    H5::H5File file((s / "samples.h5").string(), H5F_ACC_RDWR);
    const int too_many = 3;
    file.openAttribute("perturbations_in_floor").write(H5::PredType::NATIVE_INT, &too_many);
  }
  try {
    ReadSamples(s / "samples.h5");
    FAIL() << "perturbations_in_floor beyond the perturbations was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("perturbations_in_floor is 3, not 0 to 1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("samples.h5"), std::string::npos) << e.what();
  }
  // Board frames kept for a refit's joint calibration come back as written,
  // and a corner count beyond the stored corners is refused by name.
  fs::remove(s / "samples.h5");
  joint::BoardFrame frame;
  frame.frame = 7, frame.pose = 3;
  frame.colour_from_board.translation() = Eigen::Vector3d(0.1, -0.2, 1.3);
  frame.colour_corners = {{10.5f, 20.25f}, {30.0f, 40.0f}};
  frame.quad = DepthboardQuad{
      {Eigen::Vector2d(1, 2), Eigen::Vector2d(3, 4), Eigen::Vector2d(5, 6), Eigen::Vector2d(7, 8)}, 712.5, 900, 0.4};
  WriteSamples(s / "samples.h5", {sample}, {}, {frame, joint::BoardFrame{}});
  const auto frames = ReadSamples(s / "samples.h5").board_frames;
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].frame, 7);
  EXPECT_EQ(frames[0].pose, 3);
  EXPECT_DOUBLE_EQ(frames[0].colour_from_board.translation().z(), 1.3);
  ASSERT_EQ(frames[0].colour_corners.size(), 2u);
  EXPECT_FLOAT_EQ(frames[0].colour_corners[0].y, 20.25f);
  ASSERT_TRUE(frames[0].quad.has_value());
  EXPECT_DOUBLE_EQ(frames[0].quad->corners_px[3].x(), 7);
  EXPECT_EQ(frames[0].quad->board_pixels, 900);
  EXPECT_FALSE(frames[1].quad.has_value());
  {
    H5::H5File file((s / "samples.h5").string(), H5F_ACC_RDWR);
    const std::vector<int> too_many = {5, 0};
    file.openDataSet("board_frames/corner_count").write(too_many.data(), H5::PredType::NATIVE_INT);
  }
  try {
    ReadSamples(s / "samples.h5");
    FAIL() << "a corner count beyond the stored corners was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/board_frames/corner_count of frame 7 is 5"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ReadGrid(s / "missing.h5"), InputError);
}

// refit: every bad input names the problem, exits 3, and adds no version.
// A version written by the previous schemas (calibration, report and samples
// version 2: no delay, no quads section, no wall tilts, no truth sigma, no
// raw rate) still refits; the new
// version is written in the current schemas and says what the old one lacked.
TEST(Refit, ReadsVersionTwoArtifacts) {
  using namespace testing;
  ScratchDir s;
  fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", s / "session", fs::copy_options::recursive);
  const std::string session = (s / "session").string();
  ASSERT_EQ(RunTool("run-pipeline", session).exit_code, 0);
  const fs::path v1 = s / "session" / "calibrations" / "v0001";
  json c = ReadJson(v1 / "calibration.json"), r = ReadJson(v1 / "report.json");
  c["schema_version"] = 2;
  c["cameras"]["depth_from_colour"].erase("depth_delay_s");
  r["schema_version"] = 2;
  r.erase("depthboard_quads");
  for (auto& snapshot : r["planar_snapshots"]) snapshot.erase("tilt_deg");
  r["undistortion"].erase("max_wall_tilt_deg");
  std::ofstream(v1 / "calibration.json") << c.dump();
  std::ofstream(v1 / "report.json") << r.dump();
  {
    H5::H5File file((v1 / "samples.h5").string(), H5F_ACC_RDWR);
    const long long version = 2;
    file.openAttribute("schema_version").write(H5::PredType::NATIVE_LLONG, &version);
    file.unlink("truth_sigma_m");
    file.unlink("raw_rate");
  }
  const auto refit = RunTool("refit", session);
  ASSERT_EQ(refit.exit_code, 0) << refit.output;
  const fs::path v2 = s / "session" / "calibrations" / "v0002";
  const json c2 = ReadJson(v2 / "calibration.json"), r2 = ReadJson(v2 / "report.json");
  EXPECT_EQ(c2["schema_version"], kCalibrationSchemaVersion);
  EXPECT_TRUE(c2["cameras"]["depth_from_colour"]["depth_delay_s"].is_null());
  EXPECT_EQ(r2["schema_version"], kReportSchemaVersion);
  EXPECT_TRUE(r2["depthboard_quads"].contains("absent_because")) << r2["depthboard_quads"];
  ASSERT_FALSE(r2["planar_snapshots"].empty());
  EXPECT_TRUE(r2["planar_snapshots"][0]["tilt_deg"].is_null()) << "version 2 reports measured no tilts";
  EXPECT_TRUE(r2["undistortion"]["max_wall_tilt_deg"].is_null()) << r2["undistortion"];
  EXPECT_TRUE(r2["diagnosis"]["noise_floor"]["colour_pose_raw"].is_null()) << "version 2 samples carry no truth sigma";
  // Samples newer than this tool are refused, naming the versions it reads.
  {
    H5::H5File file((v2 / "samples.h5").string(), H5F_ACC_RDWR);
    const long long version = kSamplesSchemaVersion + 1;
    file.openAttribute("schema_version").write(H5::PredType::NATIVE_LLONG, &version);
  }
  const auto newer = RunTool("refit", session);
  EXPECT_EQ(newer.exit_code, 3) << newer.output;
  const std::string refused = "schema version " + std::to_string(kSamplesSchemaVersion + 1) +
                              " is not understood (this tool reads version 2 to " +
                              std::to_string(kSamplesSchemaVersion) + ")";
  EXPECT_NE(newer.output.find(refused), std::string::npos) << newer.output;
}

// Issue 47: the verdict's base-form step is a command that runs as pasted
// (it was "--model MODEL.json with "base_form": ...", for the user to
// write), quoted for a session path with a space.
TEST(Refit, TheBaseFormStepRunsAsTheVerdictWritesIt) {
  using namespace testing;
  ScratchDir s;
  const fs::path session = s / "my session";
  fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", session, fs::copy_options::recursive);
  ASSERT_EQ(RunTool("run-pipeline", "'" + session.string() + "'").exit_code, 0);
  Diagnosis d;
  d.verdict = {{VerdictPart::Kind::kBaseForm, "tangent"}};
  const std::string command = NextStepsJson(d, session.string(), (BinDir() / "refit").string())[0]["command"];
  const auto pasted = RunShell(command);
  ASSERT_EQ(pasted.exit_code, 0) << command << "\n" << pasted.output;
  EXPECT_EQ(ReadJson(session / "calibrations" / "v0002" / "calibration.json")["model_spec"]["base_form"], "tangent");
}

// Issue 46: a joint parent's cameras start the joint fit again in a refit;
// damaged ones are refused naming the field, not fitted from, nor reported
// as JSON's own error.
TEST(RefitBadInput, AJointParentsDamagedCamerasAreNamed) {
  using namespace testing;
  ScratchDir s;
  fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", s / "session", fs::copy_options::recursive);
  const std::string session = (s / "session").string();
  ASSERT_EQ(RunTool("run-pipeline", session + " --joint-cameras").exit_code, 0);
  const fs::path calibration = s / "session" / "calibrations" / "v0001" / "calibration.json";
  const json c = ReadJson(calibration);
  ASSERT_TRUE(c["cameras"]["joint"].is_object()) << c["cameras"];
  ASSERT_FALSE(ReadSamples(calibration.parent_path() / "samples.h5").board_frames.empty());
  const auto expect_bad = [&](const json& cameras, const std::string& message) {
    json damaged = c;
    damaged["cameras"] = cameras;
    std::ofstream(calibration) << damaged.dump();
    const auto result = RunTool("refit", session);
    EXPECT_EQ(result.exit_code, 3) << result.output;
    EXPECT_NE(result.output.find(message), std::string::npos) << result.output;
    EXPECT_FALSE(fs::exists(s / "session" / "calibrations" / "v0002")) << message;
  };
  json cameras = c["cameras"];
  cameras["joint"]["terms"] = json::array();
  expect_bad(cameras,
             "calibration.json: cameras.joint.terms: expected 3 kinds of observation, found an array of 0 values");
  cameras["joint"]["terms"] = json::array({{{"kind", "colour_corners"}}, 2, 3});
  expect_bad(cameras, "calibration.json: cameras.joint.terms[0]: missing required key \"unit\"");
  // A null rms is read only for a kind with no observations (schema 9).
  cameras = c["cameras"];
  cameras["joint"]["terms"][1]["rms"] = nullptr;
  expect_bad(cameras, "calibration.json: cameras.joint.terms[1]: missing required key \"rms\"");
  cameras = c["cameras"];
  cameras["depth"]["fx"] = "578";
  expect_bad(cameras, "calibration.json: cameras.depth.fx: expected a number, found \"578\"");
  cameras = c["cameras"];
  cameras["depth_from_colour"]["translation_m"][1] = nullptr;
  expect_bad(cameras, "calibration.json: cameras.depth_from_colour.translation_m[1]: expected a number, found null");
  // The joint states each camera's covariance (calibration.json 12), its diagonal the sigmas squared.
  const json &depth = c["cameras"]["depth"], &covariance = depth["covariance_fx_fy_cx_cy_k1_k2_p1_p2_k3"];
  ASSERT_EQ(covariance.size(), 81u) << depth;
  for (std::size_t i = 0; i < 9; ++i)
    EXPECT_NEAR(std::sqrt(covariance[10 * i].get<double>()), depth["stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3"][i], 1e-9);
  cameras = c["cameras"];
  cameras["depth"]["covariance_fx_fy_cx_cy_k1_k2_p1_p2_k3"].erase(80);
  expect_bad(cameras, "calibration.json: cameras.depth.covariance_fx_fy_cx_cy_k1_k2_p1_p2_k3: expected 81 numbers");
}

TEST(RefitBadInput, NamesTheProblemAndWritesNothing) {
  using namespace testing;
  ScratchDir s;
  fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", s / "session", fs::copy_options::recursive);
  const std::string session = (s / "session").string();
  auto r = RunTool("refit", session);
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("no calibration (nothing to refit"), std::string::npos) << r.output;
  ASSERT_EQ(RunTool("run-pipeline", session).exit_code, 0);
  const auto versions = [&] {
    int n = 0;
    for (const auto& e : fs::directory_iterator(s / "session" / "calibrations"))
      n += e.path().filename().string()[0] == 'v';
    return n;
  };
  const auto expect_bad = [&](const std::string& arguments, const std::string& message) {
    const auto result = RunTool("refit", session + " " + arguments);
    EXPECT_EQ(result.exit_code, 3) << arguments << ": " << result.output;
    EXPECT_NE(result.output.find(message), std::string::npos) << arguments << ": " << result.output;
    EXPECT_EQ(versions(), 1) << arguments;
  };
  // An unknown name in an option is usage (2), as CLI11's own checks are.
  for (const auto& [arguments, message] :
       {std::pair{"--add-effect no_such_effect", "unknown effect \"no_such_effect\""},
        std::pair{"--base-form cubic", "--base-form: unknown base form \"cubic\""}}) {
    const auto result = RunTool("refit", session + " " + arguments);
    EXPECT_EQ(result.exit_code, kExitUsage) << arguments << ": " << result.output;
    EXPECT_NE(result.output.find(message), std::string::npos) << arguments << ": " << result.output;
    EXPECT_EQ(versions(), 1) << arguments;
  }
  expect_bad("--from v0042", "--from v0042: no such version of " + session + " (it has v0001)");
  // Issue 47: a path to another session's version became this session's
  // newest, which apply-calibration then took by default.
  fs::copy(s / "session", s / "other", fs::copy_options::recursive);
  const std::string elsewhere = "../../other/calibrations/v0001";
  expect_bad("--from " + elsewhere, "--from " + elsewhere + ": no such version");
  std::ofstream(s / "bad_formula.json")
      << R"({"effects": [{"name": "e", "formula": "k * temperature", "parameters": [{"name": "k"}]}]})";
  expect_bad("--model " + (s / "bad_formula.json").string(), "unknown variable \"temperature\"");
  std::ofstream(s / "divide.json")
      << R"js({"effects": [{"name": "e", "formula": "k / (raw - raw)", "parameters": [{"name": "k", "initial": 1}]}]})js";
  expect_bad("--model " + (s / "divide.json").string(), "division by zero");
  // A damaged parent is refused by field before anything is fitted; it ended
  // as an internal error after the fits (issue 47's outside probe).
  const fs::path parent = s / "session" / "calibrations" / "v0001" / "calibration.json";
  const json intact = ReadJson(parent);
  json damaged = intact;
  damaged["model"]["parameters"][0]["value"] = "abc";
  std::ofstream(parent) << damaged.dump();
  expect_bad("", "calibration.json: model.parameters[0].value: expected a number, found \"abc\"");
  damaged = intact;
  damaged.erase("model");
  std::ofstream(parent) << damaged.dump();
  expect_bad("", "calibration.json: missing required key \"model\"");
  std::ofstream(parent) << intact.dump();
  // A calibration from another schema version is refused, naming both.
  const fs::path calibration = s / "session" / "calibrations" / "v0001" / "calibration.json";
  json c = ReadJson(calibration);
  c["schema_version"] = 1;
  std::ofstream(calibration) << c.dump();
  expect_bad("", "schema version 1 is not understood (this tool reads version 2 to " +
                     std::to_string(kCalibrationSchemaVersion) + ")");
  c["schema_version"] = kCalibrationSchemaVersion;
  std::ofstream(calibration) << c.dump();
  // So is a report from a newer tool.
  const fs::path report = s / "session" / "calibrations" / "v0001" / "report.json";
  json newer = ReadJson(report);
  newer["schema_version"] = kReportSchemaVersion + 1;
  std::ofstream(report) << newer.dump();
  expect_bad("", "schema version " + std::to_string(kReportSchemaVersion + 1) +
                     " is not understood (this tool reads version 2 to " + std::to_string(kReportSchemaVersion) + ")");
  newer["schema_version"] = kReportSchemaVersion;
  std::ofstream(report) << newer.dump();
  fs::remove(s / "session" / "calibrations" / "v0001" / "samples.h5");
  c["schema_version"] = 2;
  std::ofstream(calibration) << c.dump();
  expect_bad("", "samples.h5: no cached samples");
  // A version folder copied in from another session (its recordings' hashes
  // are not these) was refitted into this session's newest (issue 47's audit).
  for (auto& input : c["session"]["inputs"])
    if (input.contains("purpose")) input["sha256"] = std::string(64, '0');
  std::ofstream(calibration) << c.dump();
  expect_bad("--from v0001", "made from another session's recordings");
}

}  // namespace
}  // namespace speckle
