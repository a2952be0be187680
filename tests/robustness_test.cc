// The cases of issue 20, each tried as a new user would: ordinary-looking but
// damaged or extreme input must end with a message naming the file or field,
// a documented exit code (never 1, 134 or 139), nothing left behind, and no
// silent wrong answer.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <cmath>
#include <limits>

#include <H5Cpp.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "apply/undistortion_grid_file.h"
#include "fakenect_dump.h"
#include "pipeline/samples_file.h"
#include "recorder/recording_writer.h"
#include "robustness_util.h"
#include "schemas/atomic_folder.h"
#include "schemas/calibration_versions.h"
#include "schemas/errors.h"
#include "schemas/session_manifest.h"
#include "schemas/staging.h"
#include "stages/ceres_blocks.h"
#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;

// Ceres CHECK-fails (SIGABRT) on a block it does not hold; the helper every
// problem uses treats such a block as not estimated.
TEST(CeresBlocks, ABlockTheProblemDoesNotHoldIsNotEstimated) {
  ceres::Problem problem;
  double held[2] = {1, 2}, absent[1] = {0};
  problem.AddParameterBlock(held, 2);
  HoldConstant(problem, absent);
  BoundParameter(problem, absent, 0, -1, 1);
  EXPECT_FALSE(IsFree(problem, absent));
  EXPECT_TRUE(IsFree(problem, held));
  BoundParameter(problem, held, 1, -1e30, 5);  // "no lower bound"
  EXPECT_EQ(problem.GetParameterUpperBound(held, 1), 5);
  HoldConstant(problem, held);
  EXPECT_FALSE(IsFree(problem, held));
  EXPECT_THROW(RequireNonEmptyBlocks({2, 0}, "residual"), std::invalid_argument);
}

// One calibrated golden session, copied for each test that damages it.
class Calibrated : public ::testing::Test {
 protected:
  // ctest runs each test in its own process: the calibrated session is made
  // once per run-pipeline build (keyed by the binary's time) and shared, so a
  // sanitizer build calibrates once instead of once per test.
  static fs::path Origin() {
    const auto built = fs::last_write_time(BinDir() / "run-pipeline").time_since_epoch().count();
    const fs::path shared = BinDir() / "tests" / ("robustness_session_" + std::to_string(built));
    if (fs::exists(shared / "s" / "calibrations" / "v0001" / "undistortion_grid.h5")) return shared;
    ScratchDir made;
    CalibratedGoldenSession(made.path());
    std::error_code taken;  // another test process may have made it first
    fs::rename(made.path(), shared, taken);
    fs::create_directories(made.path());  // for ScratchDir's clean-up
    return shared;
  }
  void SetUp() override {
    const fs::path origin = Origin();
    ASSERT_TRUE(fs::exists(origin / "s" / "calibrations" / "v0001" / "undistortion_grid.h5"));
    fs::copy(origin / "s", session(), fs::copy_options::recursive);
    fs::create_directories(scratch_ / "out");
  }
  fs::path session() const { return scratch_ / "s"; }
  fs::path version() const { return session() / "calibrations" / "v0001"; }
  void EditCalibration(const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json j = ReadJson(version() / "calibration.json");
    edit(j);
    std::ofstream(version() / "calibration.json") << j.dump(2);
  }
  void EditGrid(const std::function<void(UndistortionGrid&)>& edit) {
    UndistortionGrid g = ReadGrid(version() / "undistortion_grid.h5");
    edit(g);
    fs::remove(version() / "undistortion_grid.h5");
    WriteGrid(version() / "undistortion_grid.h5", g);
  }
  CommandResult Apply(const std::string& out = "a") {
    return RunTool("apply-calibration", session().string() + " --out " + (scratch_ / "out" / out).string());
  }
  // Applying the damaged version fails naming `field`, and leaves nothing.
  void ExpectApplyRefuses(const std::string& field) {
    ExpectNamed(Apply(), kExitBadInput, field);
    EXPECT_TRUE(OnlyHolds(scratch_ / "out", {})) << "apply-calibration left something behind";
  }
  CommandResult Refit(const std::string& model_json) {
    std::ofstream(scratch_ / "model.json") << model_json;
    return RunTool("refit", session().string() + " --model " + (scratch_ / "model.json").string());
  }
  static std::string FormulaModel(const std::string& formula, const std::string& parameters) {
    return R"({"schema_version": 2, "base_form": "reciprocal", "undistortion": "off", "effects": [)"
           R"({"name": "f", "formula": ")" +
           formula + R"(", "parameters": )" + parameters + "}]}";
  }
  bool OnlyFirstVersion() const { return CalibrationVersions(session()).size() == 1; }

  ScratchDir scratch_;
};

// --- calibrations: every number checked before use ---

TEST_F(Calibrated, IntactCalibrationApplies) { EXPECT_EQ(Apply().exit_code, 0) << Apply("b").output; }

// Issue 47: read as an int, an image width of 4294967936 wrapped to 640 and
// the calibration was applied as if it were VGA.
TEST_F(Calibrated, ImageSizeBeyondIntIsRefusedNotWrapped) {
  EditCalibration([](nlohmann::json& j) { j["cameras"]["depth"]["image_size"] = {4294967936ull, 480}; });
  ExpectApplyRefuses("cameras.depth.image_size: expected a width and height of 1 to 100000 pixels, found 4294967936");
}

TEST_F(Calibrated, AnImageSizeOfThreeValuesIsRefused) {
  EditCalibration([](nlohmann::json& j) { j["cameras"]["depth"]["image_size"] = {640, 480, 3}; });
  ExpectApplyRefuses("cameras.depth.image_size: expected [width, height], found 3 values");
}

TEST_F(Calibrated, FractionalImageSizeIsRefused) {
  EditCalibration([](nlohmann::json& j) { j["cameras"]["colour"]["image_size"] = {640.5, 480}; });
  ExpectApplyRefuses("cameras.colour.image_size");
}

TEST_F(Calibrated, HugePrincipalPointIsRefused) {
  EditCalibration([](nlohmann::json& j) { j["cameras"]["depth"]["cx"] = 1e308; });
  ExpectApplyRefuses("cameras.depth.cx");
}

TEST_F(Calibrated, HugeDistortionIsRefused) {
  EditCalibration([](nlohmann::json& j) { j["cameras"]["colour"]["distortion_k1_k2_p1_p2_k3"][0] = 1e300; });
  ExpectApplyRefuses("cameras.colour.distortion_k1_k2_p1_p2_k3[0]");
}

TEST_F(Calibrated, HugeBaseParameterIsRefused) {
  EditCalibration([](nlohmann::json& j) { j["model"]["parameters"][0]["value"] = 1e308; });
  ExpectApplyRefuses("model.parameters");
}

TEST_F(Calibrated, ModelWithNoDepthIsRefused) {
  EditCalibration([](nlohmann::json& j) {
    j["model"]["parameters"][0]["value"] = 0.0;
    j["model"]["parameters"][1]["value"] = 0.0;
  });
  ExpectApplyRefuses("model.parameters: the base form maps");
}

// Issue 47's probe: b negated, every depth a sensor can see falls at
// negative raw values; apply-calibration wrote empty clouds with exit 0.
TEST_F(Calibrated, ModelWhoseDepthsLieAtNoRealRawValueIsRefused) {
  EditCalibration([](nlohmann::json& j) {
    j["model"]["parameters"][1]["value"] = -j["model"]["parameters"][1]["value"].get<double>();
  });
  ExpectApplyRefuses("outside the raw values a sensor sends (0 to 2047)");
}

// A string where a rotation's numbers go is named by its field.
TEST_F(Calibrated, ExtrinsicsOfTheWrongTypeAreNamedByTheirField) {
  EditCalibration([](nlohmann::json& j) { j["cameras"]["depth_from_colour"]["rotation_axis_angle_rad"] = "abc"; });
  ExpectApplyRefuses("cameras.depth_from_colour.rotation_axis_angle_rad: expected a list of numbers");
}

// --- undistortion grids ---

TEST_F(Calibrated, GridWithNanExtentIsRefused) {
  EditGrid([](UndistortionGrid& g) { g.x_max = std::nan(""); });
  ExpectApplyRefuses("undistortion_grid.h5: extent_x_min_x_max_y_min_y_max");
}

TEST_F(Calibrated, GridWithEqualNodesIsRefused) {
  EditGrid([](UndistortionGrid& g) { g.raw_nodes[1] = g.raw_nodes[0]; });
  ExpectApplyRefuses("raw_nodes[1]: expected nodes increasing");
}

TEST_F(Calibrated, GridWithReversedNodesIsRefused) {
  EditGrid([](UndistortionGrid& g) { std::reverse(g.raw_nodes.begin(), g.raw_nodes.end()); });
  ExpectApplyRefuses("raw_nodes[1]: expected nodes increasing");
}

TEST_F(Calibrated, GridWithNodesBelowOneRawIsRefusedNotHung) {
  EditGrid([](UndistortionGrid& g) {
    for (std::size_t k = 0; k < g.raw_nodes.size(); ++k) g.raw_nodes[k] = 700 + 1e-3 * static_cast<double>(k);
  });
  const auto start = std::chrono::steady_clock::now();
  ExpectApplyRefuses("raw_nodes[1]: expected nodes increasing by at least 1");
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(30));
}

TEST_F(Calibrated, GridWithZeroLengthAxisIsRefused) {
  EditGrid([](UndistortionGrid& g) {
    g.nx = 0;
    g.correction.clear(), g.std_error.clear(), g.supported.clear();
  });
  ExpectApplyRefuses("undistortion_grid.h5");
}

// --- fits that fail say so ---

TEST_F(Calibrated, FormulaWithoutParametersIsRefused) {
  ExpectNamed(Refit(FormulaModel("raw * 0.001", "[]")), kExitBadInput, "expected 1 to 300 parameters");
  EXPECT_TRUE(OnlyFirstVersion());
}

// Issue 22 raised the cap from 20 to 300 (a linear formula's terms are computed
// once per sample): beyond it the refit is still refused before any fit.
TEST_F(Calibrated, FormulaWithTooManyParametersIsRefusedAtOnce) {
  nlohmann::json parameters = nlohmann::json::array();
  std::string formula = "0";
  for (int i = 0; i < 301; ++i) {
    parameters.push_back({{"name", "p" + std::to_string(i)}});
    formula += " + p" + std::to_string(i);
  }
  const auto start = std::chrono::steady_clock::now();
  ExpectNamed(Refit(FormulaModel(formula, parameters.dump())), kExitBadInput, "found 301");
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(30));
}

TEST_F(Calibrated, FitWithNanDerivativeIsNotFitted) {
  const auto r = Refit(FormulaModel("sqrt(k) * (raw - 700)", R"([{"name": "k", "initial": 0, "lower": 0}])"));
  ExpectNamed(r, kExitBadInput, "could not be fitted");
  EXPECT_TRUE(OnlyFirstVersion());
}

TEST_F(Calibrated, FitWithInfiniteResidualsIsNotFitted) {
  const auto r = Refit(FormulaModel("1e300 + k", R"([{"name": "k"}])"));
  ExpectNamed(r, kExitBadInput, "could not be fitted");
  EXPECT_EQ(r.output.find("inf raw"), std::string::npos) << r.output;
  EXPECT_TRUE(OnlyFirstVersion()) << "a version was written for a failed fit";
}

TEST_F(Calibrated, SamplesOfOnePoseAreNotCalledComplete) {
  CachedSamples cached = ReadSamples(version() / "samples.h5");
  const int pose = cached.samples.front().pose;
  CachedSamples one;
  one.perturbations.depths.resize(cached.perturbations.size());
  one.perturbations.in_floor = cached.perturbations.in_floor;
  for (std::size_t i = 0; i < cached.samples.size(); ++i) {
    if (cached.samples[i].pose != pose) continue;
    one.samples.push_back(cached.samples[i]);
    for (std::size_t k = 0; k < cached.perturbations.size(); ++k)
      one.perturbations.depths[k].push_back(cached.perturbations.depths[k][i]);
  }
  ASSERT_GT(one.samples.size(), 20u);
  fs::remove(version() / "samples.h5");
  WriteSamples(version() / "samples.h5", one.samples, one.perturbations);
  const auto r = RunTool("refit", session().string());
  ExpectNamed(r, kExitBadInput, "no held-out error");
  EXPECT_EQ(r.output.find("complete"), std::string::npos) << r.output;
  EXPECT_TRUE(OnlyFirstVersion());
}

// Issue 47: samples.h5 with an infinite or negative true depth gave the
// verdict "as good as the cameras allow". Refit names the sample instead.
TEST_F(Calibrated, SamplesWithImpossibleDepthsAreRefusedNamingTheSample) {
  const CachedSamples cached = ReadSamples(version() / "samples.h5");
  for (const double impossible : {std::numeric_limits<double>::infinity(), -1.5}) {
    CachedSamples damaged = cached;
    damaged.samples[7].depth_m = impossible;
    fs::remove(version() / "samples.h5");
    WriteSamples(version() / "samples.h5", damaged.samples, damaged.perturbations);
    const auto r = RunTool("refit", session().string());
    ExpectNamed(r, kExitBadInput, "/depth_m of sample 7 is");
    EXPECT_TRUE(OnlyFirstVersion());
  }
  CachedSamples damaged = cached;
  ASSERT_FALSE(damaged.perturbations.depths.empty());
  damaged.perturbations.depths[0][3] = std::nan("");
  fs::remove(version() / "samples.h5");
  WriteSamples(version() / "samples.h5", damaged.samples, damaged.perturbations);
  ExpectNamed(RunTool("refit", session().string()), kExitBadInput, "/perturbed_depth_m of sample 3 (perturbation 0)");
}

// --- versions, symlinks, leftovers ---

TEST_F(Calibrated, AbsurdVersionFoldersAreNamedAndSkipped) {
  fs::create_directories(session() / "calibrations" / "v99999999999");
  fs::create_directories(session() / "calibrations" / "v2147483647");
  const auto r = RunTool("refit", session().string() + " --from v0001");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("v99999999999: ignored"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(session() / "calibrations" / "v0002")) << r.output;
  for (const auto& e : fs::directory_iterator(session() / "calibrations"))
    EXPECT_EQ(e.path().filename().string().find("v-"), std::string::npos) << e.path();
}

TEST_F(Calibrated, SymlinkedCalibrationsAreNotWrittenThrough) {
  fs::create_directories(scratch_ / "elsewhere");
  fs::rename(session() / "calibrations", scratch_ / "elsewhere" / "calibrations");
  fs::create_directory_symlink(scratch_ / "elsewhere" / "calibrations", session() / "calibrations");
  const auto r = RunTool("run-pipeline", session().string());
  ExpectNamed(r, kExitBadInput, "symbolic link");
  EXPECT_FALSE(fs::exists(scratch_ / "elsewhere" / "calibrations" / "v0002"));
}

TEST_F(Calibrated, StaleIncomingOfADeadRunIsRemoved) {
  const fs::path stale = LeftoverOfADeadTool(session() / "calibrations", true);
  ASSERT_FALSE(stale.empty());
  ASSERT_TRUE(fs::exists(stale / kStagingMarker));
  const auto r = RunTool("refit", session().string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_NE(r.output.find("no longer running"), std::string::npos) << r.output;
}

TEST_F(Calibrated, StalePartialOutputOfADeadApplyIsRemoved) {
  const fs::path stale = LeftoverOfADeadTool(scratch_ / "out");
  ASSERT_FALSE(stale.empty());
  const auto r = Apply();
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_NE(r.output.find("no longer running"), std::string::npos) << r.output;
}

// Issue 47: the clean-up removed any folder beside --out whose name looked like
// staging, its owner's number not running (PID 0 counted), with everything in
// it. The user's own folders and files are never touched, whatever their name.
TEST_F(Calibrated, UsersOwnFoldersBesideOutAreLeft) {
  const std::string dead = std::to_string(DeadPid());
  const fs::path out = scratch_ / "out";
  const std::vector<std::string> folders = {".photos.partial-" + dead,          // no number after the PID
                                            ".photos.partial-0-1",              // PID 0
                                            ".thesis.partial-" + dead + "-12",  // the exact pattern, no marker
                                            ".incoming-" + dead + "-3",         // the exact pattern, no marker
                                            ".marked.partial-" + dead + "-4",   // a marker naming another process
                                            ".linked.partial-" + dead + "-5"};  // a link to a folder with a marker
  for (const std::string& f : folders) {
    fs::create_directories(out / f);
    std::ofstream(out / f / "notes.txt") << "mine";
  }
  std::ofstream(out / (".marked.partial-" + dead + "-4") / kStagingMarker) << "speckle staging folder of process 1\n";
  const fs::path marked_elsewhere = LeftoverOfADeadTool(scratch_ / "elsewhere");
  ASSERT_FALSE(marked_elsewhere.empty());
  fs::remove_all(out / (".linked.partial-" + dead + "-5"));
  fs::create_directory_symlink(marked_elsewhere, out / (".linked.partial-" + dead + "-5"));
  std::ofstream(out / (".draft.partial-" + dead + "-6")) << "a file that is no HDF5 recording";

  const auto r = Apply();
  EXPECT_EQ(r.exit_code, 0) << r.output;
  for (const std::string& f : folders) {
    if (f.rfind(".linked", 0) == 0) continue;
    EXPECT_TRUE(fs::exists(out / f / "notes.txt")) << f << " was removed:\n" << r.output;
  }
  EXPECT_TRUE(fs::is_symlink(out / (".linked.partial-" + dead + "-5"))) << r.output;
  EXPECT_TRUE(fs::exists(marked_elsewhere / "calibration.json")) << r.output;
  EXPECT_TRUE(fs::exists(out / (".draft.partial-" + dead + "-6"))) << r.output;
  EXPECT_EQ(r.output.find("removing"), std::string::npos) << r.output;
}

// A staged recording (session_append stages files, not folders) of a killed
// add is removed: a regular file named exactly so that starts as HDF5 does,
// or is still empty (killed before HDF5 wrote a byte: issue 47's outside
// probe found one left in the session for good).
TEST_F(Calibrated, StagedRecordingOfADeadAddIsRemovedAndOtherFilesAreNot) {
  const std::string dead = std::to_string(DeadPid());
  const fs::path out = scratch_ / "out";
  fs::copy_file(version() / "samples.h5", out / (".planar.h5.partial-" + dead + "-77"));
  std::ofstream(out / (".planar.h5.partial-" + dead + "-78")) << "not HDF5";
  std::ofstream(out / (".planar-2.h5.partial-" + dead + "-79"));
  const auto r = Apply();
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(out / (".planar.h5.partial-" + dead + "-77"))) << r.output;
  EXPECT_TRUE(fs::exists(out / (".planar.h5.partial-" + dead + "-78"))) << r.output;
  EXPECT_FALSE(fs::exists(out / (".planar-2.h5.partial-" + dead + "-79"))) << r.output;
}

TEST_F(Calibrated, PartialOutputOfARunningProcessIsLeft) {
  const fs::path running = scratch_ / "out" / (".b.partial-" + std::to_string(getpid()) + "-7");
  fs::create_directories(running);
  EXPECT_EQ(Apply().exit_code, 0);
  EXPECT_TRUE(fs::exists(running));
}

// --calibration takes what check and compare take: a session (its newest
// version) too; a session was "S/calibration.json: missing" (issue 47's probe).
TEST_F(Calibrated, ASessionGivenAsTheCalibrationIsItsNewestVersion) {
  const auto r = RunTool("apply-calibration", session().string() + " --calibration " + session().string() + " --out " +
                                                  (scratch_ / "out" / "a").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(ReadJson(scratch_ / "out" / "a" / "applied.json").dump().find("v0001"), std::string::npos);
}

// A session whose every version was flagged implausible is said to have no
// usable calibration; the newest was said to be passed by and then loaded,
// and refused on a field (issue 47's outside probe).
TEST_F(Calibrated, ASessionWithOnlyFlaggedVersionsHasNoUsableCalibration) {
  EditCalibration([](nlohmann::json& j) {
    j["plausibility"] = {{"problems", {"cameras.depth.fy -319899.6 px is -499.84 image widths"}}, {"accepted", false}};
  });
  for (const std::string& tool : {"apply-calibration", "measure"}) {
    const auto r =
        RunTool(tool, session().string() + (tool == "measure" ? " --from 100,100 --to 200,100"
                                                              : " --out " + (scratch_ / "out" / "a").string()));
    EXPECT_EQ(r.exit_code, kExitBadInput) << tool << ": " << r.output;
    EXPECT_NE(r.output.find("no usable calibration: every version (v0001) was flagged"), std::string::npos)
        << tool << ": " << r.output;
  }
}

TEST_F(Calibrated, OutWithTrailingSlashIsNormalized) {
  const auto r = RunTool("apply-calibration", session().string() + " --out " + (scratch_ / "out" / "a").string() + "/");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(scratch_ / "out" / "a" / "applied.json"));
  EXPECT_TRUE(OnlyHolds(scratch_ / "out", {"a"}));
}

TEST_F(Calibrated, EmptyOutIsRefused) {
  ExpectNamed(RunTool("apply-calibration", session().string() + " --out ''"), kExitBadInput, "--out");
}

}  // namespace
}  // namespace speckle
