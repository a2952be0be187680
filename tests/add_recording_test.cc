// record-session --add-to: the boards dump and the walls dump, recorded
// separately with libfreenect `record`, become one session; every refusal and
// every failure while writing leaves the session exactly as it was (same
// files, same session.json bytes).
#include <H5Cpp.h>
#include <gtest/gtest.h>

#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "fakenect_dump.h"
#include "recorder/recording_reader.h"
#include "recorder/recording_writer.h"
#include "recorder/session_append.h"
#include "schemas/errors.h"
#include "schemas/session_manifest.h"
#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;

// Every name in the session folder (hidden ones too) and session.json's bytes.
struct SessionSnapshot {
  std::set<std::string> names;
  std::string manifest_bytes;
  bool operator==(const SessionSnapshot&) const = default;
};

SessionSnapshot Snapshot(const fs::path& session) {
  SessionSnapshot s;
  if (!fs::exists(session)) return s;
  for (const auto& entry : fs::directory_iterator(session)) s.names.insert(entry.path().filename().string());
  std::ifstream in(session / kSessionFileName, std::ios::binary);
  s.manifest_bytes.assign(std::istreambuf_iterator<char>(in), {});
  return s;
}

std::string Names(const SessionSnapshot& s) {
  std::string text;
  for (const auto& n : s.names) text += n + " ";
  return text;
}

class AddRecording : public ::testing::Test {
 protected:
  fs::path Session() const { return scratch_ / "s"; }
  fs::path BoardsDump() const { return MakeDump(scratch_ / "boards", 3, 3, 0.001, 700); }
  fs::path WallsDump() const { return MakeDump(scratch_ / "walls", 4, 0, 0.001, 900); }

  // The boards dump as a new session's depthboard recording.
  void ImportBoards(const std::string& extra = "") {
    const auto r = RunTool("record-session", "fakenect:" + BoardsDump().string() + " --purpose depthboard " + extra +
                                                 " --out " + Session().string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  CommandResult Add(const std::string& source, const std::string& extra) const {
    return RunTool("record-session", source + " " + extra + " --add-to " + Session().string());
  }
  // Runs an add that must be refused with exit 3, naming `expected` in its
  // message, and leave the session untouched.
  void ExpectRefused(const std::string& source, const std::string& extra, const std::string& expected) {
    const SessionSnapshot before = Snapshot(Session());
    const CommandResult r = Add(source, extra);
    EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
    EXPECT_NE(r.output.find(expected), std::string::npos) << "message should say \"" << expected << "\":\n" << r.output;
    const SessionSnapshot after = Snapshot(Session());
    EXPECT_EQ(after.names, before.names) << "before: " << Names(before) << "\nafter: " << Names(after);
    EXPECT_TRUE(after.manifest_bytes == before.manifest_bytes) << "session.json changed";
    std::cout << r.output;  // the message a user sees, for the record
  }

  ScratchDir scratch_;
};

TEST_F(AddRecording, BoardsDumpAndWallsDumpBecomeOneSession) {
  ImportBoards();
  const CommandResult add = Add("fakenect:" + WallsDump().string(), "--purpose planar");
  ASSERT_EQ(add.exit_code, 0) << add.output;

  EXPECT_EQ(Snapshot(Session()).names, (std::set<std::string>{"depthboard.h5", "planar.h5", "session.json"}));
  const SessionManifest m = ReadSessionManifest(Session());
  ASSERT_EQ(m.recordings.size(), 2u);
  EXPECT_EQ(m.recordings[0].file, "depthboard.h5");
  EXPECT_EQ(m.recordings[0].purpose, RecordingPurpose::kDepthboard);
  EXPECT_EQ(m.recordings[0].source_path, fs::absolute(BoardsDump()).string());
  EXPECT_EQ(m.recordings[1].file, "planar.h5");
  EXPECT_EQ(m.recordings[1].purpose, RecordingPurpose::kPlanar);
  EXPECT_EQ(m.recordings[1].source, "fakenect");
  EXPECT_EQ(m.recordings[1].source_path, fs::absolute(WallsDump()).string());
  EXPECT_EQ(m.driver, "libfreenect");

  // The walls recording holds the walls dump's frames (raw 900), not the boards'.
  const RecordingReader walls(Session() / "planar.h5");
  ASSERT_EQ(walls.frame_count(), 4);
  EXPECT_EQ(walls.ReadFrame(3).depth.image.at<std::uint16_t>(240, 320), 900);
  EXPECT_EQ(RecordingReader(Session() / "depthboard.h5").ReadFrame(0).depth.image.at<std::uint16_t>(0, 0), 700);

  const CommandResult info = RunTool("session-info", Session().string());
  EXPECT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("depthboard.h5 (depthboard, from fakenect)"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("planar.h5 (planar, from fakenect)"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find(fs::absolute(WallsDump()).string()), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("valid: yes"), std::string::npos) << info.output;
}

TEST_F(AddRecording, WallsFirstThenBoardsTakesTheRigFromTheAdd) {
  const auto walls =
      RunTool("record-session", "fakenect:" + WallsDump().string() + " --purpose planar --out " + Session().string());
  ASSERT_EQ(walls.exit_code, 0) << walls.output;
  const CommandResult add =
      Add("fakenect:" + BoardsDump().string(), "--purpose depthboard --squares 9x7 --square-size 0.04");
  ASSERT_EQ(add.exit_code, 0) << add.output;
  const SessionManifest m = ReadSessionManifest(Session());
  ASSERT_TRUE(m.rig.has_value());
  EXPECT_EQ(m.rig->squares_x, 9);
  EXPECT_EQ(m.recordings.size(), 2u);
}

TEST_F(AddRecording, RefusesAPurposeTheSessionAlreadyHas) {
  ImportBoards();
  ExpectRefused("fakenect:" + WallsDump().string(), "--purpose depthboard",
                "the session already has a depthboard recording (depthboard.h5, from fakenect");
}

TEST_F(AddRecording, RefusesAFileTheSessionDoesNotList) {
  ImportBoards();
  WriteFile(Session() / "planar.h5", "left over");
  ExpectRefused("fakenect:" + WallsDump().string(), "--purpose planar", "session.json does not list it");
}

TEST_F(AddRecording, RefusesAnotherImageSize) {
  ImportBoards();
  // A toolbox frame folder whose colour camera ran at 1280x1024.
  fs::create_directories(scratch_ / "frames");
  cv::imwrite((scratch_ / "frames" / "0001-c1.png").string(), cv::Mat(1024, 1280, CV_8UC3, cv::Scalar(60, 60, 60)));
  WriteFile(scratch_ / "frames" / "0001-d.pgm", DepthPgm(640, 480, 2047, false, 700));
  ExpectRefused("frames:" + (scratch_ / "frames").string(), "--purpose free",
                "image size: colour 1280x1024 in the new free.h5 differs from 640x480 in depthboard.h5");
}

TEST_F(AddRecording, RefusesAnotherSerial) {
  ImportBoards("--serial A00362913019035A");
  ExpectRefused("fakenect:" + WallsDump().string(), "--purpose planar --serial B00367707227042B",
                "sensor.serial: the session has \"A00362913019035A\", the new recording \"B00367707227042B\"");
}

// libfreenect's device.json holds one Kinect's factory registration; two
// dumps with different ones came from two sensors.
TEST_F(AddRecording, RefusesAnotherKinectsRegistration) {
  const fs::path boards = BoardsDump();
  WriteFile(boards / "device.json", R"({"reg_info": {"ax": 1830}, "const_shift": 200})");
  ImportBoards();
  const fs::path walls = WallsDump();
  WriteFile(walls / "device.json", R"({"reg_info": {"ax": 1845}, "const_shift": 203})");
  ExpectRefused(
      "fakenect:" + walls.string(), "--purpose planar",
      "sensor: the new planar.h5's device.json (factory registration constants) differs from depthboard.h5's");
  WriteFile(walls / "device.json", R"({"const_shift": 200, "reg_info": {"ax": 1830}})");  // same unit, keys reordered
  const CommandResult same = Add("fakenect:" + walls.string(), "--purpose planar");
  EXPECT_EQ(same.exit_code, 0) << same.output;
}

// A session in millimetres from another driver (as a Kinect v2 importer
// would write it), made through the library.
TEST_F(AddRecording, RefusesAnotherDriverAndDepthUnitsNamingBoth) {
  fs::create_directories(Session());
  RecordingHeader header;
  header.purpose = RecordingPurpose::kDepthboard;
  header.source = "frames";
  header.depth_size = cv::Size(640, 480);
  header.depth_units = DepthUnits::kMillimetre;
  {
    RecordingWriter writer(Session() / "depthboard.h5", header);
    FramePair frame;
    frame.depth.image = cv::Mat(480, 640, CV_16UC1, cv::Scalar(1500));
    writer.Append(std::move(frame));
    writer.Close();
  }
  SessionManifest m;
  m.driver = "openni2";
  m.depth_units = DepthUnits::kMillimetre;
  m.recordings = {{"depthboard.h5", RecordingPurpose::kDepthboard, "frames", ""}};
  WriteSessionManifest(Session(), m);
  ExpectRefused("fakenect:" + WallsDump().string(), "--purpose planar",
                "driver: the session has \"openni2\", the new recording \"libfreenect\"");
  ExpectRefused("fakenect:" + WallsDump().string(), "--purpose planar",
                "depth_units: the session holds millimetre depth, planar.h5 would hold raw_11bit");
}

TEST_F(AddRecording, RefusesAMissingSession) {
  ExpectRefused("fakenect:" + WallsDump().string(), "--purpose planar", "no such session directory");
  EXPECT_FALSE(fs::exists(Session())) << "the add must not create the session";
  fs::create_directories(Session());
  ExpectRefused("fakenect:" + WallsDump().string(), "--purpose planar", "holds no session.json");
  EXPECT_TRUE(fs::is_empty(Session()));
}

TEST_F(AddRecording, RefusesAnUnknownSessionVersion) {
  ImportBoards();
  nlohmann::json json = ReadJson(Session() / kSessionFileName);
  json["schema_version"] = 99;
  WriteFile(Session() / kSessionFileName, json.dump(2));
  ExpectRefused("fakenect:" + WallsDump().string(), "--purpose planar", "session schema version 99");
}

TEST_F(AddRecording, CorruptFrameHalfWayLeavesNothingBehind) {
  ImportBoards();
  const fs::path walls = WallsDump();
  // The third depth frame keeps its size (so the dump passes the checks made
  // before writing) but is no longer a P5 file: the writer meets it mid-way.
  std::vector<fs::path> depth_files;
  for (const auto& e : fs::directory_iterator(walls))
    if (e.path().filename().string().starts_with("d-")) depth_files.push_back(e.path());
  std::sort(depth_files.begin(), depth_files.end());
  std::fstream victim(depth_files[2], std::ios::in | std::ios::out | std::ios::binary);
  victim.write("P6", 2);
  victim.close();
  ExpectRefused("fakenect:" + walls.string(), "--purpose planar", depth_files[2].filename().string());
}

// Yields `frames` depth frames and runs `meddle` before the last one: another
// tool touching the session while the add is writing.
class MeddlingSource : public FrameSource {
 public:
  MeddlingSource(int frames, std::function<void()> meddle) : frames_(frames), meddle_(std::move(meddle)) {}
  std::optional<FramePair> Next() override {
    if (next_ == frames_) return std::nullopt;
    if (++next_ == frames_) meddle_();
    FramePair frame;
    frame.depth.image = cv::Mat(480, 640, CV_16UC1, cv::Scalar(900));
    return frame;
  }

 private:
  int frames_, next_ = 0;
  std::function<void()> meddle_;
};

// The last step before session.json is replaced: the recording is already
// under its final name, and must go again when the replacement cannot happen.
TEST_F(AddRecording, SessionJsonChangedDuringTheAddRemovesTheLinkedRecording) {
  ImportBoards();
  const SessionSnapshot before = Snapshot(Session());
  const std::string meddled = before.manifest_bytes + "\n";
  SessionPlan plan;
  plan.manifest = ReadSessionToAppendTo(Session());
  PlannedRecording walls;
  walls.file = "planar.h5";
  walls.header.purpose = RecordingPurpose::kPlanar;
  walls.header.source = "fakenect";
  walls.header.depth_size = cv::Size(640, 480);
  walls.source = std::make_unique<MeddlingSource>(3, [&] { WriteFile(Session() / kSessionFileName, meddled); });
  plan.recordings.push_back(std::move(walls));
  try {
    AppendToSession(std::move(plan), Session());
    ADD_FAILURE() << "the add should have seen session.json change";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("changed while recording"), std::string::npos) << e.what();
  }
  const SessionSnapshot after = Snapshot(Session());
  EXPECT_EQ(after.names, before.names) << "after: " << Names(after);
  EXPECT_TRUE(after.manifest_bytes == meddled) << "the other tool's session.json must survive";
}

TEST_F(AddRecording, OutAndAddToTogetherIsAUsageError) {
  ImportBoards();
  const SessionSnapshot before = Snapshot(Session());
  const CommandResult r = RunTool("record-session", "fakenect:" + WallsDump().string() + " --out " +
                                                        (scratch_ / "t").string() + " --add-to " + Session().string());
  EXPECT_EQ(r.exit_code, kExitUsage) << r.output;
  EXPECT_TRUE(Snapshot(Session()) == before);
  EXPECT_FALSE(fs::exists(scratch_ / "t"));
  const CommandResult neither = RunTool("record-session", "fakenect:" + WallsDump().string());
  EXPECT_EQ(neither.exit_code, kExitUsage) << neither.output;
  EXPECT_NE(neither.output.find("--add-to"), std::string::npos) << neither.output;
}

// Walls recorded as the floor: the summary warns with the commonest reason
// (it used to end with exit 0 and a count), and the report keeps each
// rejected snapshot's segmented "wall" for the page to show. The golden
// scenario's wall frames are overwritten with the sensor looking down at a
// floor 0.6 m below (nominal Kinect), with no reading above it.
TEST(AddRecordingEndToEnd, WallsThatAreAllFloorAreWarnedAbout) {
  ScratchDir scratch;
  const std::string scenario = (fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "scenario.json").string();
  const fs::path session = scratch / "s";
  const auto recorded = RunTool("record-session", "sim --scenario " + scenario + " --out " + session.string());
  ASSERT_EQ(recorded.exit_code, 0) << recorded.output;
  {
    H5::H5File file((session / "planar.h5").string(), H5F_ACC_RDWR);
    H5::DataSet frames = file.openDataSet("depth/frames");
    hsize_t dims[3];
    frames.getSpace().getSimpleExtentDims(dims);
    ASSERT_EQ(dims[1] * dims[2], 480u * 640u);
    std::vector<std::uint16_t> floor(dims[0] * dims[1] * dims[2]);
    for (std::size_t i = 0; i < floor.size(); ++i) {
      const double y = (static_cast<double>(i / 640 % 480) - 240) / 580.0;
      floor[i] = y > -0.3 ? static_cast<std::uint16_t>(std::lround(((y + 0.3) / 0.4 - 3.3309) / -0.0030711)) : 2047;
    }
    frames.write(floor.data(), H5::PredType::NATIVE_UINT16);
  }
  const auto run = RunTool("run-pipeline", session.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("0 of 4 planar (wall) frames kept"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("warning      only 0 of 4 wall snapshots were kept; 4 were rejected because failed "
                            "segmentation: the dominant plane is tilted"),
            std::string::npos)
      << run.output;
  const nlohmann::json report = ReadJson(session / "calibrations" / "v0001" / "report.json");
  int masks = 0;
  for (const auto& f : report["frames"])
    if (f["recording"] == "planar" && f.contains("wall_mask")) masks += f["wall_mask"]["runs"].size() > 1;
  EXPECT_EQ(masks, 4) << "each rejected floor keeps its segmented region";
}

// End to end on simulated frames: the boards and the walls recorded by two
// record-session runs (as two dumps would be) calibrate as one session.
TEST(AddRecordingEndToEnd, SimulatedBoardsThenWallsCalibrate) {
  ScratchDir scratch;
  const std::string scenario = (fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "scenario.json").string();
  const fs::path session = scratch / "s";
  const auto boards =
      RunTool("record-session", "sim --scenario " + scenario + " --purpose depthboard --out " + session.string());
  ASSERT_EQ(boards.exit_code, 0) << boards.output;
  ASSERT_EQ(ReadSessionManifest(session).recordings.size(), 1u) << "--purpose keeps only the boards";
  const auto walls =
      RunTool("record-session", "sim --scenario " + scenario + " --purpose planar --add-to " + session.string());
  ASSERT_EQ(walls.exit_code, 0) << walls.output;

  const auto run = RunTool("run-pipeline", session.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("; 4 of 4 planar (wall) frames kept"), std::string::npos)
      << "the added walls must be used:\n"
      << run.output;
  const nlohmann::json calibration = ReadJson(session / "calibrations" / "v0001" / "calibration.json");
  std::set<std::string> inputs;
  for (const auto& input : calibration["session"]["inputs"]) inputs.insert(input["file"]);
  EXPECT_EQ(inputs, (std::set<std::string>{"session.json", "depthboard.h5", "planar.h5"}));
}

}  // namespace
}  // namespace speckle
