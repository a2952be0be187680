// The cases of issue 20 on the input side, each tried as a new user would:
// JSON that is too deep or repeats keys, recordings whose datasets cannot be
// read, and imports that store only what they validated. Each ends with a
// message naming the file or field and a documented exit code.
#include <gtest/gtest.h>

#include <H5Cpp.h>

#include <sys/stat.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "fakenect_dump.h"
#include "recorder/recording_writer.h"
#include "robustness_util.h"
#include "schemas/errors.h"
#include "schemas/h5_access.h"
#include "schemas/session_manifest.h"
#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;

// --- JSON that is too deep, repeats keys or has fractional versions ---

TEST(BadJson, DeeplyNestedModelIsRefusedWithoutOverflow) {
  ScratchDir s;
  std::ofstream(s / "model.json") << std::string(200000, '[') << std::string(200000, ']');
  fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", s / "s", fs::copy_options::recursive);
  ExpectNamed(RunTool("run-pipeline", (s / "s").string() + " --model " + (s / "model.json").string()), kExitBadInput,
              "nested deeper than 64");
}

TEST(BadJson, DeeplyNestedScenarioIsRefusedWithoutOverflow) {
  ScratchDir s;
  std::ofstream(s / "sc.json") << "{\"a\":" << std::string(200000, '[') << std::string(200000, ']') << "}";
  ExpectNamed(RunTool("record-session", "sim --scenario " + (s / "sc.json").string() + " --out " + (s / "o").string()),
              kExitBadInput, "nested deeper than 64");
  EXPECT_FALSE(fs::exists(s / "o"));
}

class BadManifest : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", s_ / "s", fs::copy_options::recursive);
    text_ = ReadJson(s_ / "s" / "session.json").dump();
  }
  CommandResult Info(const std::string& text) {
    std::ofstream(s_ / "s" / "session.json") << text;
    return RunTool("session-info", (s_ / "s").string());
  }
  ScratchDir s_;
  std::string text_;
};

TEST_F(BadManifest, DeeplyNested) {
  ExpectNamed(Info(std::string(200000, '[') + std::string(200000, ']')), kExitBadInput, "nested deeper than 64");
  std::string objects;
  for (int i = 0; i < 200000; ++i) objects += "{\"a\":";
  ExpectNamed(Info(objects + "1" + std::string(200000, '}')), kExitBadInput, "nested deeper than 64");
}

TEST_F(BadManifest, FractionalSchemaVersion) {
  nlohmann::json j = nlohmann::json::parse(text_);
  j["schema_version"] = j["schema_version"].get<int>() + 0.9;
  ExpectNamed(Info(j.dump()), kExitBadInput, "schema_version: expected an integer, found");
}

TEST_F(BadManifest, DuplicateKey) {
  ASSERT_EQ(text_.front(), '{');
  ExpectNamed(Info("{\"driver\": \"x\"," + text_.substr(1)), kExitBadInput, "key \"driver\" appears twice");
}

// --- recordings whose datasets cannot be read ---

// --- a camera given with standard deviations (a prior, issue 46) ---

nlohmann::json GivenCamera(const nlohmann::json& stddev) {
  nlohmann::json c = {{"image_size", {640, 480}}, {"fx", 525.0}, {"fy", 525.0}, {"cx", 319.5}, {"cy", 239.5}};
  if (!stddev.is_null()) c["stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3"] = stddev;
  return c;
}

TEST(GivenCamera, StandardDeviationsAreReadAndWrittenBackOnlyWhenGiven) {
  const KnownIntrinsics prior =
      IntrinsicsFromJson(GivenCamera({5.0, 5.0, 3.0, 3.0, 0.01, 0.01, 0, 0, 0}), "session.json: cameras.colour");
  EXPECT_TRUE(prior.HasPrior());
  EXPECT_EQ(prior.stddev[2], 3.0);
  EXPECT_EQ(IntrinsicsFromJson(ToJson(prior), "again").stddev, prior.stddev);
  const KnownIntrinsics exact = IntrinsicsFromJson(GivenCamera(nullptr), "session.json: cameras.colour");
  EXPECT_FALSE(exact.HasPrior());
  EXPECT_FALSE(ToJson(exact).contains("stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3")) << "an exact camera is written as before";
}

TEST(GivenCamera, ImpossibleStandardDeviationsAreRefusedNamingTheTerm) {
  const std::pair<nlohmann::json, std::string> cases[] = {
      {{5.0, 5.0, -3.0, 3.0, 0, 0, 0, 0, 0}, "stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3[2]: the standard deviation of cx"},
      {{400.0, 5.0, 3.0, 3.0, 0, 0, 0, 0, 0}, "the standard deviation of fx must lie in [0, 262.5]"},
      {{5.0, 5.0, 3.0}, "expected 9 numbers"}};
  for (const auto& [stddev, named] : cases) {
    try {
      IntrinsicsFromJson(GivenCamera(stddev), "session.json: cameras.colour");
      ADD_FAILURE() << stddev.dump() << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
  }
}

// At the door: record-session --describe refuses an impossible sigma with
// exit 3 naming the term, before anything is recorded.
TEST(GivenCamera, RecordSessionRefusesAnImpossibleSigmaBeforeRecording) {
  ScratchDir s;
  std::ofstream(s / "describe.json")
      << nlohmann::json{{"cameras", {{"colour", GivenCamera({5.0, 5.0, -3.0, 3.0, 0, 0, 0, 0, 0})}}}}.dump();
  const auto r =
      RunTool("record-session", "sim --describe " + (s / "describe.json").string() + " --out " + (s / "x").string());
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3[2]: the standard deviation of cx"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(s / "x")) << "nothing recorded";
}

// A camera file (issue 48) without standard deviations is neither taken as
// exact silently nor given made-up sigmas: the user is asked for one or the
// other. A camera for other images is refused. All before recording.
// A ROS ost.yaml of a colour camera for images `width` wide, in `dir`.
std::string OstYaml(const fs::path& dir, int width) {
  std::ofstream(dir / "ost.yaml") << "image_width: " << width
                                  << "\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n  data: [529.3, 0, "
                                     "306.2, 0, 528.6, 258.3, 0, 0, 1]\ndistortion_model: plumb_bob\n"
                                     "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n";
  return (dir / "ost.yaml").string();
}

TEST(GivenCamera, RecordSessionAsksForACameraFilesSigmasAndRefusesAnotherImageSize) {
  ScratchDir s;
  const auto ost = [&](int width) { return OstYaml(s.path(), width); };
  auto r = RunTool("record-session", "sim --colour-camera " + ost(640) + " --out " + (s / "x").string());
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("gives no standard deviations"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--colour-camera-sigma 2,2,2,2"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--colour-camera-exact"), std::string::npos) << r.output;
  r = RunTool("record-session",
              "sim --colour-camera " + ost(1280) + " --colour-camera-sigma 1,1,1,1 --out " + (s / "x").string());
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("the colour camera given (--colour-camera " + ost(1280) +
                          ") is for 1280x480 images, but depthboard.h5 holds 640x480 colour images"),
            std::string::npos)
      << r.output;
  r = RunTool("record-session",
              "sim --colour-camera " + ost(640) + " --colour-camera-sigma 1,1,x,1 --out " + (s / "x").string());
  EXPECT_EQ(r.exit_code, 2) << "a malformed option value is usage: " << r.output;
  EXPECT_NE(r.output.find("--colour-camera-sigma 1,1,x,1: expected 4 or 9 standard deviations"), std::string::npos)
      << r.output;
  // Typed where a session.json goes, it is pointed to the camera flag instead of read as broken JSON.
  r = RunTool("record-session", "sim --describe " + ost(640) + " --out " + (s / "x").string());
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("a camera file goes in with --colour-camera"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(s / "x")) << "nothing recorded";
}

// A camera of another image size in --describe's session.json is refused
// before recording, as a camera file is; one written into session.json
// afterwards is a problem session-info names (it said "valid: yes").
TEST(GivenCamera, ACameraOfAnotherImageSizeIsRefusedInDescribeAndNamedBySessionInfo) {
  ScratchDir s;
  std::ofstream(s / "scenario.json") << R"({"schema_version": 1, "depthboard": {"poses": 2, "frames_per_pose": 1},
    "planar": {"snapshots": 0}, "ir_chessboard": {"poses": 0}})";
  auto r = RunTool("record-session", "sim --scenario " + (s / "scenario.json").string() +
                                         " --colour-camera-exact --colour-camera " + OstYaml(s.path(), 640) +
                                         " --out " + (s / "given").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(RunTool("session-info", (s / "given").string()).exit_code, 0);
  nlohmann::json session = ReadJson(s / "given" / "session.json");
  ASSERT_TRUE(session["cameras"]["colour"].contains("image_size")) << session.dump();
  session["cameras"]["colour"]["image_size"] = {1280, 480};
  std::ofstream(s / "describe.json") << nlohmann::json{{"cameras", session["cameras"]}}.dump();
  r = RunTool("record-session", "sim --scenario " + (s / "scenario.json").string() + " --describe " +
                                    (s / "describe.json").string() + " --out " + (s / "x").string());
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("the colour camera given (--describe's cameras.colour) is for 1280x480"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(s / "x")) << "nothing recorded";
  std::ofstream(s / "given" / "session.json") << session.dump(2);
  r = RunTool("session-info", (s / "given").string());
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("its colour images are 640x480, but session.json's cameras.colour is for 1280x480 images"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("valid: NO"), std::string::npos) << r.output;
}

// Issue 47's probe: --square-size without --squares was ignored, and the
// simulator wrote a --squares board into session.json that its frames do not
// show (the pipeline then fitted nonsense for minutes). Both refused before
// recording.
TEST(BoardFlags, ASquareSizeAloneAndASimulatedBoardDescribedOtherwiseAreRefused) {
  ScratchDir s;
  auto r = RunTool("record-session", "sim --square-size 40 --out " + (s / "x").string());
  EXPECT_EQ(r.exit_code, 2) << "an option without its companion is usage: " << r.output;
  EXPECT_NE(r.output.find("needs --squares"), std::string::npos) << r.output;
  r = RunTool("record-session", "sim --squares 8x6 --square-size 0.04 --out " + (s / "x").string());
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("the simulator draws its scenario's board, 11x8 squares"), std::string::npos) << r.output;
  // Issue 47's probe: 65x7 was written to a session.json that its own reader refuses (each side 2..64).
  r = RunTool("record-session", "sim --squares 65x7 --square-size 0.04 --out " + (s / "x").string());
  EXPECT_EQ(r.exit_code, 2) << "an option's value outside its range is usage: " << r.output;
  EXPECT_NE(r.output.find("--squares: expected COLSxROWS of chessboard squares, each 2 to 64"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(s / "x")) << "nothing recorded";
  // Issue 47's outside probe: "9x7x2" was taken as 9x7, a seed of -1 as
  // 18446744073709551615, and a --describe file of a newer schema relabelled.
  r = RunTool("record-session", "sim --squares 11x8x2 --square-size 0.0223 --out " + (s / "x").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("found \"11x8x2\""), std::string::npos) << r.output;
  r = RunTool("record-session", "sim --seed -1 --out " + (s / "x").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("a seed is 0 or more"), std::string::npos) << r.output;
  std::ofstream(s / "newer.json") << R"({"schema": "speckle.session", "schema_version": 7, "notes": "n"})";
  r = RunTool("record-session", "sim --describe " + (s / "newer.json").string() + " --out " + (s / "x").string());
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("schema version 7 is not understood"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(s / "x")) << "nothing recorded";
}

TEST(DamagedRecording, ClockOfStringsIsBadInputNotAbort) {
  ScratchDir s;
  fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", s / "s", fs::copy_options::recursive);
  fs::path recording;
  for (const auto& e : fs::directory_iterator(s / "s"))
    if (e.path().extension() == ".h5") recording = e.path();
  ASSERT_FALSE(recording.empty());
  {
    H5::H5File file(recording.string(), H5F_ACC_RDWR);
    const hsize_t n = file.openDataSet("/depth/host_time_ns").getSpace().getSimpleExtentNpoints();
    file.unlink("/depth/host_time_ns");
    const H5::StrType text(H5::PredType::C_S1, 8);
    const H5::DataSpace space(1, &n);
    std::vector<char> bytes(n * 8, 'x');
    file.createDataSet("/depth/host_time_ns", text, space).write(bytes.data(), text);
  }
  const auto info = RunTool("session-info", (s / "s").string());
  EXPECT_EQ(info.exit_code, kExitBadInput) << info.output;
  EXPECT_NE(info.output.find("host_time_ns"), std::string::npos) << info.output;
  const auto run = RunTool("run-pipeline", (s / "s").string());
  EXPECT_EQ(run.exit_code, kExitBadInput) << run.output;
}

// Issue 47's probe: frames claiming 100000 x 100000 pixels (a chunked
// dataset costs nothing on disk until written) are refused by name before a
// frame is read, not allocated at 20 GB each.
TEST(DamagedRecording, FramesClaimingHugeDimensionsAreRefusedByName) {
  ScratchDir s;
  fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", s / "s", fs::copy_options::recursive);
  {
    H5::H5File file((s / "s" / "depthboard.h5").string(), H5F_ACC_RDWR);
    const hsize_t n = h5::Dimensions(file.openDataSet("/depth/frames"))[0];
    file.unlink("/depth/frames");
    const hsize_t dims[3] = {n, 100000, 100000}, chunk[3] = {1, 64, 64};
    H5::DSetCreatPropList chunked;
    chunked.setChunk(3, chunk);
    file.createDataSet("/depth/frames", H5::PredType::NATIVE_UINT16, H5::DataSpace(3, dims), chunked);
  }
  for (const std::string tool : {"session-info", "run-pipeline"})
    ExpectNamed(RunTool(tool, (s / "s").string()), kExitBadInput, "claims 100000 x 100000 pixel frames");
}

// A frame chunk overwritten with garbage (szip decodes it without complaint):
// session-info calls the session invalid and names the frame, run-pipeline
// skips that frame with the same reason and calibrates from the rest.
TEST(DamagedRecording, GarbageFrameChunkIsNamedBySessionInfoAndSkippedByRunPipeline) {
  ScratchDir s;
  fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", s / "s", fs::copy_options::recursive);
  {
    H5::H5File file((s / "s" / "depthboard.h5").string(), H5F_ACC_RDWR);
    const H5::DataSet frames = file.openDataSet("/depth/frames");
    const hsize_t offset[3] = {3, 0, 0};
    const std::vector<std::uint8_t> garbage(64, 0xff);
    ASSERT_GE(H5Dwrite_chunk(frames.getId(), H5P_DEFAULT, 0, offset, garbage.size(), garbage.data()), 0);
  }
  ExpectNamed(RunTool("session-info", (s / "s").string()), kExitBadInput, "frame 3: depth value");
  const auto run = RunTool("run-pipeline", (s / "s").string());
  ASSERT_EQ(run.exit_code, kExitOk) << run.output;
  const nlohmann::json report = ReadJson(s / "s" / "calibrations" / "v0001" / "report.json");
  int skipped = 0;
  for (const auto& f : report["frames"]) {
    if (f["recording"] != "depthboard" || f["index"] != 3) continue;
    EXPECT_EQ(f["rejected_by"], "read") << f.dump();
    EXPECT_NE(f["reason"].get<std::string>().find("frame 3: depth value"), std::string::npos) << f.dump();
    ++skipped;
  }
  EXPECT_EQ(skipped, 1);
}

// session.json and a recording's own header disagree on the depth units:
// every tool says so, not only session-info.
TEST(DamagedRecording, ManifestDisagreeingWithItsRecordingIsRefusedByEveryTool) {
  ScratchDir s;
  fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", s / "s", fs::copy_options::recursive);
  ASSERT_EQ(RunTool("run-pipeline", (s / "s").string()).exit_code, kExitOk);
  nlohmann::json manifest = ReadJson(s / "s" / "session.json");
  manifest["depth_units"] = "millimetre";
  std::ofstream(s / "s" / "session.json") << manifest.dump(2);
  const std::string names = "depth units raw_11bit differ from session.json's millimetre";
  ExpectNamed(RunTool("session-info", (s / "s").string()), kExitBadInput, names);
  ExpectNamed(RunTool("run-pipeline", (s / "s").string()), kExitBadInput, names);
  ExpectNamed(RunTool("apply-calibration", (s / "s").string() + " --out " + (s / "out").string()), kExitBadInput,
              names);
  EXPECT_FALSE(fs::exists(s / "out"));
}

// --- imports store only what they validated ---

struct Import {
  CommandResult result;
  bool nothing_left = false;
};

Import ImportInto(const ScratchDir& s, const std::string& source) {
  fs::create_directories(s / "out");
  Import i;
  i.result = RunTool("record-session", source + " --out " + (s / "out" / "s").string());
  i.nothing_left = OnlyHolds(s / "out", {});
  return i;
}

void ExpectImportRefused(const Import& i, const std::string& names) {
  ExpectNamed(i.result, kExitBadInput, names);
  EXPECT_TRUE(i.nothing_left) << "a partial session was left behind";
}

std::string ColourJpeg() {
  cv::Mat image(480, 640, CV_8UC3);
  cv::randu(image, 0, 255);
  std::vector<unsigned char> bytes;
  cv::imencode(".jpg", image, bytes);
  return {bytes.begin(), bytes.end()};
}

void WriteFrames(const fs::path& dir, const std::string& colour_jpeg, int frames = 2) {
  fs::create_directories(dir);
  for (int i = 0; i < frames; ++i) {
    WriteFile(dir / ("000" + std::to_string(i) + "-d.pgm"), DepthPgm(640, 480, 2047, false, 700));
    WriteFile(dir / ("000" + std::to_string(i) + "-c1.jpg"), colour_jpeg);
  }
}

TEST(ValidatedImport, IntactFramesImport) {
  ScratchDir s;
  WriteFrames(s / "frames", ColourJpeg());
  const Import i = ImportInto(s, "frames:" + (s / "frames").string());
  EXPECT_EQ(i.result.exit_code, 0) << i.result.output;
}

TEST(ValidatedImport, TruncatedJpegFailsTheFrame) {
  ScratchDir s;
  WriteFrames(s / "frames", ColourJpeg());
  const std::string jpeg = ColourJpeg();
  WriteFile(s / "frames" / "0001-c1.jpg", jpeg.substr(0, jpeg.size() / 2));
  ExpectImportRefused(ImportInto(s, "frames:" + (s / "frames").string()), "0001-c1.jpg: truncated JPEG");
}

TEST(ValidatedImport, AbsurdClaimedJpegSizeIsRefusedBeforeDecoding) {
  ScratchDir s;
  std::string jpeg = ColourJpeg();
  const std::size_t sof = jpeg.find("\xFF\xC0");
  ASSERT_NE(sof, std::string::npos);
  for (std::size_t at : {sof + 5, sof + 7}) jpeg[at] = '\x3E', jpeg[at + 1] = '\x80';  // 16000
  WriteFrames(s / "frames", jpeg, 1);
  ExpectImportRefused(ImportInto(s, "frames:" + (s / "frames").string()), "claims 16000x16000");
}

TEST(ValidatedImport, PgmValueAboveMaxvalIsRefused) {
  ScratchDir s;
  WriteFrames(s / "frames", ColourJpeg(), 1);
  WriteFile(s / "frames" / "0000-d.pgm", DepthPgm(640, 480, 2047, false, 3000));
  ExpectImportRefused(ImportInto(s, "frames:" + (s / "frames").string()), "above the header's maxval 2047");
}

TEST(ValidatedImport, TwentyDigitFrameNumberIsNamed) {
  ScratchDir s;
  fs::create_directories(s / "frames");
  WriteFile(s / "frames" / "12345678901234567890-d.pgm", DepthPgm(640, 480, 2047, false, 700));
  ExpectImportRefused(ImportInto(s, "frames:" + (s / "frames").string()),
                      "frame number 12345678901234567890 is out of range");
}

TEST(ValidatedImport, DuplicateIndexLinesAreRefused) {
  ScratchDir s;
  MakeDump(s / "dump", 2, 2);
  std::ifstream in(s / "dump" / "INDEX.txt");
  const std::string index{std::istreambuf_iterator<char>(in), {}};
  WriteFile(s / "dump" / "INDEX.txt", index + index);
  ExpectImportRefused(ImportInto(s, "fakenect:" + (s / "dump").string()), "is listed twice");
}

TEST(ValidatedImport, TwentyDigitIndexTimeIsNamed) {
  ScratchDir s;
  MakeDump(s / "dump", 1, 0);
  const std::string name = "d-12345678901234567890.5-7.pgm";
  WriteFile(s / "dump" / name, DepthPgm(640, 480, 65535, true, 700));
  std::ofstream(s / "dump" / "INDEX.txt", std::ios::app) << name << "\n";
  ExpectImportRefused(ImportInto(s, "fakenect:" + (s / "dump").string()), "INDEX.txt:2: time");
}

TEST(ValidatedImport, DeviceJsonFolderIsNamed) {
  ScratchDir s;
  MakeDump(s / "dump", 2, 2);
  fs::create_directories(s / "dump" / "device.json");
  ExpectImportRefused(ImportInto(s, "fakenect:" + (s / "dump").string()), "device.json: is a folder");
}

TEST(ValidatedImport, StalePartialOfADeadImportIsRemoved) {
  ScratchDir s;
  MakeDump(s / "dump", 2, 2);
  fs::create_directories(s / "out");
  const fs::path stale = LeftoverOfADeadTool(s / "out");
  ASSERT_FALSE(stale.empty());
  const auto r =
      RunTool("record-session", "fakenect:" + (s / "dump").string() + " --out " + (s / "out" / "t").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_NE(r.output.find("no longer running"), std::string::npos) << r.output;
}

// Issue 47: compare given a version folder whose calibration.json is a
// pipe blocked on it; check reads calibrations the same way.
TEST(BadPath, ACalibrationJsonThatIsAPipeIsRefusedAtOnce) {
  ScratchDir s;
  fs::create_directories(s / "v0001");
  ASSERT_EQ(mkfifo((s / "v0001" / "calibration.json").c_str(), 0600), 0);
  for (const std::string tool : {"compare", "check"}) {
    const auto r = RunShell("timeout 60 " + (BinDir() / tool).string() + " " + (s / "v0001").string() + " " +
                            (tool == "check" ? s.path() : s / "v0001").string());
    EXPECT_EQ(r.exit_code, kExitBadInput) << tool << ": " << r.output;
    EXPECT_NE(r.output.find("calibration.json: not a regular file"), std::string::npos) << tool << ": " << r.output;
  }
}

// Issue 47's trial: `check --threads -1` printed CLI11's bound for a double,
// 0 to a 309-digit number. Every bound a user can break reads as a short line.
TEST(Usage, ANegativeCountIsRefusedWithAReadableBound) {
  for (const std::string args :
       {"check a b --threads -1", "run-pipeline a --threads -1", "measure a --frame -1 --from 1,1 --to 2,2"}) {
    const auto r = RunShell((BinDir() / args.substr(0, args.find(' '))).string() + args.substr(args.find(' ')));
    EXPECT_EQ(r.exit_code, kExitUsage) << args << ": " << r.output;
    EXPECT_LT(r.output.find('\n'), 80u) << args << ": " << r.output;
    EXPECT_EQ(r.output.find("0000000"), std::string::npos) << args << ": " << r.output;
  }
}

}  // namespace
}  // namespace speckle
