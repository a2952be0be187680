// Every kind of bad input gets a message naming the file or field and what was
// expected, a non-zero exit code, and no partial session left behind.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <H5Cpp.h>

#include <fstream>
#include <thread>

#include "fakenect_dump.h"
#include "recorder/recording_reader.h"
#include "recorder/recording_writer.h"
#include "schemas/errors.h"
#include "schemas/session_manifest.h"
#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;

struct Outcome {
  CommandResult result;
  bool nothing_left = false;
};

Outcome Import(const ScratchDir& scratch, const std::string& source, const std::string& extra = "") {
  fs::create_directories(scratch / "out");
  Outcome o;
  o.result = RunTool("record-session", source + " " + extra + " --out " + (scratch / "out" / "s").string());
  o.nothing_left = OnlyHolds(scratch / "out", {});
  return o;
}

void ExpectRejected(const Outcome& o, const std::string& names) {
  EXPECT_EQ(o.result.exit_code, kExitBadInput) << o.result.output;
  EXPECT_NE(o.result.output.find(names), std::string::npos) << "message should name " << names << ":\n"
                                                            << o.result.output;
  EXPECT_TRUE(o.nothing_left) << "a partial session was left behind";
}

TEST(BadFakenectDump, MissingIndex) {
  ScratchDir s;
  fs::create_directories(s / "dump");
  ExpectRejected(Import(s, "fakenect:" + (s / "dump").string()), "INDEX.txt");
}

TEST(BadFakenectDump, MalformedIndexLine) {
  ScratchDir s;
  MakeDump(s / "dump", 2, 0);
  std::ofstream(s / "dump" / "INDEX.txt", std::ios::app) << "x-12.0-7.pgm\n";
  ExpectRejected(Import(s, "fakenect:" + (s / "dump").string()), "INDEX.txt:3");
}

TEST(BadFakenectDump, ListedFileMissing) {
  ScratchDir s;
  MakeDump(s / "dump", 2, 0);
  std::ofstream(s / "dump" / "INDEX.txt", std::ios::app) << "d-1234.5-99.pgm\n";
  ExpectRejected(Import(s, "fakenect:" + (s / "dump").string()), "d-1234.5-99.pgm");
}

TEST(BadFakenectDump, TruncatedPgm) {
  ScratchDir s;
  MakeDump(s / "dump", 3, 0);
  fs::path victim;
  for (const auto& e : fs::directory_iterator(s / "dump"))
    if (e.path().filename().string()[0] == 'd') victim = e.path();
  fs::resize_file(victim, 1000);
  ExpectRejected(Import(s, "fakenect:" + (s / "dump").string()), victim.filename().string());
}

TEST(BadFakenectDump, EmptyDump) {
  ScratchDir s;
  fs::create_directories(s / "dump");
  WriteFile(s / "dump" / "INDEX.txt", "");
  ExpectRejected(Import(s, "fakenect:" + (s / "dump").string()), "empty");
}

TEST(BadFakenectDump, UnpairedFramesRejectedUnlessAllowed) {
  ScratchDir s;
  MakeDump(s / "dump", 4, 4, /*colour_offset_s=*/0.5);  // colour half a second late
  ExpectRejected(Import(s, "fakenect:" + (s / "dump").string()), "no partner");
  const Outcome allowed = Import(s, "fakenect:" + (s / "dump").string(), "--allow-unpaired");
  EXPECT_EQ(allowed.result.exit_code, 0) << allowed.result.output;
}

TEST(BadFakenectDump, PairedDumpImports) {
  ScratchDir s;
  MakeDump(s / "dump", 3, 3);
  const Outcome o = Import(s, "fakenect:" + (s / "dump").string());
  EXPECT_EQ(o.result.exit_code, 0) << o.result.output;
}

TEST(BadFrameFolder, WrongMaxval) {
  ScratchDir s;
  fs::create_directories(s / "frames");
  WriteFile(s / "frames" / "0000-d.pgm", DepthPgm(640, 480, 255, false, 200));
  ExpectRejected(Import(s, "frames:" + (s / "frames").string()), "maxval 255, expected 2047 or 2048");
}

TEST(BadFrameFolder, WrongSize) {
  ScratchDir s;
  fs::create_directories(s / "frames");
  WriteFile(s / "frames" / "0000-d.pgm", DepthPgm(320, 240, 2047, false, 700));
  ExpectRejected(Import(s, "frames:" + (s / "frames").string()), "0000-d.pgm: frame is 320x240, expected 640x480");
}

TEST(BadFrameFolder, UnreadableColour) {
  ScratchDir s;
  fs::create_directories(s / "frames");
  WriteFile(s / "frames" / "0000-d.pgm", DepthPgm(640, 480, 2047, false, 700));
  WriteFile(s / "frames" / "0000-c1.jpg", "this is not a jpeg");
  ExpectRejected(Import(s, "frames:" + (s / "frames").string()), "0000-c1.jpg");
}

TEST(BadScenario, UnknownKeyIsNamed) {
  ScratchDir s;
  WriteFile(s / "sc.json", R"({"depthboard": {"posses": 3}})");
  ExpectRejected(Import(s, "sim", "--scenario " + (s / "sc.json").string()), "unknown key \"posses\"");
  // The keys it knows are listed, though the file gave none of them (the list was empty).
  ExpectRejected(Import(s, "sim", "--scenario " + (s / "sc.json").string()),
                 "(known keys: frames_per_pose, max_depth_m, max_tilt_deg, min_depth_m, poses, seconds_between_poses)");
}

TEST(BadScenario, OutOfRangeValueIsNamed) {
  ScratchDir s;
  WriteFile(s / "sc.json", R"({"depth_model": {"raw_noise_sigma": -1}})");
  ExpectRejected(Import(s, "sim", "--scenario " + (s / "sc.json").string()), "depth_model.raw_noise_sigma");
}

// Scenarios whose keys are each in range but that together give nothing to
// calibrate from are refused before a frame is rendered (they recorded
// sessions every later step refused).
TEST(BadScenario, NothingUsableIsRefusedBeforeRecording) {
  const std::pair<const char*, const char*> cases[] = {
      {R"({"depthboard": {"poses": 0}, "planar": {"snapshots": 0}, "ir_chessboard": {"poses": 0}})", "records nothing"},
      // IR images alone (issue 47's outside probe: recorded, exit 0, then
      // refused by run-pipeline)
      {R"({"depthboard": {"poses": 0}, "planar": {"snapshots": 0}})", "records nothing to calibrate depth from"},
      {R"({"depth_model": {"max_raw": 300}})", "the board at 0.6-1.5 m"},
      {R"({"depth_model": {"min_depth_m": 4}, "depthboard": {"poses": 0}})", "the wall at 0.6-3 m"},
      {R"({"rig": {"square_size_m": 0.005}, "depthboard": {"max_depth_m": 5}})", "rig.square_size_m"},
      {R"({"rig": {"squares_x": 30, "squares_y": 30, "square_size_m": 0.2}})", "no board pose keeps the board"},
      {R"({"cameras": {"colour": {"intrinsics": [1, 1, 320, 240]}}})", "cameras.colour.intrinsics: focal lengths"},
      {R"({"cameras": {"ir": {"intrinsics": [580, 580, 900, 240]}}})", "cameras.ir.intrinsics: principal point"},
      {R"({"cameras": {"ir": {"distortion": [80, 0, 0, 0, 0]}}})", "cameras.ir.distortion"}};
  for (const auto& [scenario, names] : cases) {
    SCOPED_TRACE(scenario);
    ScratchDir s;
    WriteFile(s / "sc.json", scenario);
    ExpectRejected(Import(s, "sim", "--scenario " + (s / "sc.json").string()), names);
  }
  // Asked for by purpose, IR images alone are made (to add to a session).
  ScratchDir s;
  WriteFile(s / "ir.json",
            R"({"depthboard": {"poses": 0}, "planar": {"snapshots": 0}, "ir_chessboard": {"poses": 1}})");
  const auto ir = RunTool("record-session", "sim --purpose ir_chessboard --scenario " + (s / "ir.json").string() +
                                                " --out " + (s / "ir").string());
  EXPECT_EQ(ir.exit_code, 0) << ir.output;
}

// The joint calibration (the default) or the separate steps: both at once is a usage error.
TEST(Usage, JointAndSeparateCamerasTogetherAreAUsageError) {
  ScratchDir s;
  const auto r = RunTool("run-pipeline", (s / "session").string() + " --joint-cameras --separate-cameras");
  EXPECT_EQ(r.exit_code, kExitUsage) << r.output;
  EXPECT_NE(r.output.find("--separate-cameras"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::is_empty(s.path())) << "nothing written";
}

TEST(Usage, UnknownSourceIsAUsageError) {
  ScratchDir s;
  const auto r = RunTool("record-session", "camera:/dev/video0 --out " + (s / "x").string());
  EXPECT_EQ(r.exit_code, kExitUsage) << r.output;
  // The kinds come from apps/sources/source_table.cc; this pins the message
  // users (and scripts) have seen since before the table.
  EXPECT_NE(r.output.find("expected sim, freenect, fakenect:DIR, frames:DIR, tum:DIR or rosbag:FILE, found "
                          "\"camera:/dev/video0\""),
            std::string::npos)
      << r.output;
}

// A kind that takes a path without one, a path given to one that takes none,
// and --seed beside any source but the simulator are usage errors too.
TEST(Usage, SourcePathAndSeedMustFitTheKind) {
  ScratchDir s;
  for (const std::string& source :
       std::vector<std::string>{"fakenect", "tum:", "sim:" + s.path().string(), "freenect:0"}) {
    const auto r = RunTool("record-session", source + " --out " + (s / "x").string());
    EXPECT_EQ(r.exit_code, kExitUsage) << source << "\n" << r.output;
    EXPECT_NE(r.output.find("expected sim, freenect"), std::string::npos) << r.output;
  }
  const auto r = RunTool("record-session", "frames:" + s.path().string() + " --seed 3 --out " + (s / "x").string());
  EXPECT_EQ(r.exit_code, kExitUsage) << r.output;
  EXPECT_NE(r.output.find("only the simulator (SOURCE sim) has a seed"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(s / "x"));
}

// --help lists every kind with its description, from the same table.
TEST(Usage, HelpListsEverySourceKind) {
  const auto r = RunTool("record-session", "--help");
  EXPECT_EQ(r.exit_code, kExitOk) << r.output;
  for (const char* kind : {"sim ", "freenect ", "fakenect:DIR ", "frames:DIR ", "tum:DIR ", "rosbag:FILE "}) {
    EXPECT_NE(r.output.find(std::string("\n  ") + kind), std::string::npos) << kind << "\n" << r.output;
  }
  EXPECT_NE(r.output.find("sim | freenect | fakenect:DIR | frames:DIR | tum:DIR | rosbag:FILE"), std::string::npos)
      << r.output;
}

TEST(Usage, ExistingSessionIsNotOverwritten) {
  ScratchDir s;
  fs::create_directories(s / "existing");
  const auto r = RunTool("record-session", "sim --out " + (s / "existing").string());
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
  EXPECT_NE(r.output.find("already exists"), std::string::npos);
}

// A path the command line names that is not there is bad input (3), named,
// in every tool: not a usage error (2) from the argument parser.
// Issue 47: a square size in millimetres typed as metres imported a whole
// session that only run-pipeline refused, and 0 or a negative size was said
// to be missing. Each is refused before anything is written, naming the flag
// and the unit.
TEST(SquareSize, ImpossibleSizesAreRefusedBeforeRecordingNamingTheUnit) {
  ScratchDir s;
  const std::vector<std::pair<std::string, std::string>> cases{{"40", "0.04"},  // millimetres as metres
                                                               {"0", "positive"},
                                                               {"-0.03", "positive"},
                                                               {"0.0004", "metres"}};
  for (const auto& [size, names] : cases) {
    const fs::path out = s / ("s" + size);
    const auto r = RunTool("record-session", "sim --squares 9x7 --square-size " + size + " --out " + out.string());
    EXPECT_EQ(r.exit_code, kExitUsage) << size << "\n" << r.output;  // an option's value outside its range
    EXPECT_NE(r.output.find("--square-size " + size), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(names), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out)) << "a session was written for --square-size " << size;
  }
  const auto missing = RunTool("record-session", "sim --squares 9x7 --out " + (s / "m").string());
  EXPECT_EQ(missing.exit_code, kExitUsage) << missing.output;
  EXPECT_NE(missing.output.find("--squares needs --square-size"), std::string::npos) << missing.output;
}

TEST(BadPath, AMissingSessionModelOrScenarioIsBadInputNamingIt) {
  ScratchDir s;
  fs::create_directories(s / "empty");
  const std::string missing = (s / "nosuch").string();
  const std::vector<std::pair<std::string, std::string>> runs{
      {"run-pipeline", missing},
      {"refit", missing},
      {"run-pipeline", (s / "empty").string() + " --model " + missing + ".json"},
      {"refit", (s / "empty").string() + " --model " + missing + ".json"},
      {"record-session", "sim --scenario " + missing + ".json --out " + (s / "new").string()}};
  for (const auto& [tool, arguments] : runs) {
    const auto r = RunTool(tool, arguments);
    EXPECT_EQ(r.exit_code, kExitBadInput) << tool << " " << arguments << "\n" << r.output;
    EXPECT_NE(r.output.find(missing), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("no such"), std::string::npos) << r.output;
  }
  EXPECT_FALSE(fs::exists(s / "new"));
}

// --- damaged sessions and recordings, seen through session-info ---

class DamagedSession : public ::testing::Test {
 protected:
  void SetUp() override {
    RecordingHeader h;
    h.purpose = RecordingPurpose::kDepthboard;
    h.source = "test";
    h.depth_size = cv::Size(8, 6);
    {
      RecordingWriter writer(scratch_ / "s" / "depthboard.h5", (fs::create_directories(scratch_ / "s"), h));
      FramePair f;
      f.depth.image = cv::Mat(6, 8, CV_16UC1, cv::Scalar(700));
      writer.Append(f);
    }
    SessionManifest m;
    m.driver = "test";
    m.recordings = {{"depthboard.h5", RecordingPurpose::kDepthboard, "", ""}};
    WriteSessionManifest(scratch_ / "s", m);
  }
  CommandResult Info() { return RunTool("session-info", (scratch_ / "s").string()); }
  fs::path Recording() { return scratch_ / "s" / "depthboard.h5"; }
  ScratchDir scratch_;
};

TEST_F(DamagedSession, IntactSessionIsValid) { EXPECT_EQ(Info().exit_code, 0) << Info().output; }

// Issue 47: session.json as a FIFO blocked every reader for ever, and one
// linked to /dev/zero was read without bound. Both are refused at once,
// named; `timeout` turns a hang into a failure instead of a stuck suite.
TEST_F(DamagedSession, SessionJsonThatIsAPipeOrADeviceIsRefusedAtOnce) {
  const fs::path manifest = scratch_ / "s" / "session.json";
  const std::string info = "timeout 60 " + (BinDir() / "session-info").string() + " " + (scratch_ / "s").string();
  fs::remove(manifest);
  ASSERT_EQ(mkfifo(manifest.c_str(), 0600), 0);
  auto r = RunShell(info);
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
  EXPECT_NE(r.output.find("session.json: is not a regular file"), std::string::npos) << r.output;
  fs::remove(manifest);
  fs::create_symlink("/dev/zero", manifest);
  r = RunShell(info);
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
  EXPECT_NE(r.output.find("session.json: is not a regular file"), std::string::npos) << r.output;
}

// Issue 47: session-info printed session.json's strings raw, so a driver
// name could clear the terminal or forge "valid: yes" under a broken session.
TEST_F(DamagedSession, StringsFromTheSessionCannotDriveTheTerminalOrForgeALine) {
  SessionManifest m = ReadSessionManifest(scratch_ / "s");
  m.sensor.model = "Kinect\x1b[2J";
  m.driver = "test\n\nvalid: yes";
  m.optics =
      "stock\xc2\x9b"
      "31m";  // UTF-8's C1 CSI
  m.sensor.label =
      "unit \xe2\x80\xae"
      "7 tinu";  // U+202E: the rest of the line shown right to left
  WriteSessionManifest(scratch_ / "s", m);
  fs::remove(Recording());
  WriteFile(Recording(), "plain text");  // a real problem, so the summary must say NO
  const auto r = Info();
  EXPECT_EQ(r.output.find('\x1b'), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("\xc2\x9b"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("\nvalid: yes"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("Kinect\\x1b[2J"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("\xe2\x80\xae"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("unit \\u202e7 tinu"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("test\\x0a\\x0avalid: yes"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\nvalid: NO"), std::string::npos) << r.output;
}

// Issue 47: session-info said "valid: yes" for host times no recording holds.
TEST_F(DamagedSession, HostTimesNoRecordingHoldsAreProblems) {
  const auto record = [&](std::int64_t first_ns, std::int64_t second_ns) {
    fs::remove(Recording());
    RecordingHeader h;
    h.purpose = RecordingPurpose::kDepthboard;
    h.source = "test";
    h.depth_size = cv::Size(8, 6);
    RecordingWriter writer(Recording(), h);
    for (const std::int64_t t : {first_ns, second_ns}) {
      FramePair f;
      f.depth.image = cv::Mat(6, 8, CV_16UC1, cv::Scalar(700));
      f.depth.host_time_ns = t;
      writer.Append(f);
    }
  };
  constexpr std::int64_t kDay = 86'400'000'000'000;
  record(1'700'000'000'000'000'000, 1'700'000'000'000'000'000 + kDay / 2);  // half a day: possible
  EXPECT_EQ(Info().exit_code, 0) << Info().output;
  record(1'700'000'000'000'000'000, -5);
  auto r = Info();
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
  EXPECT_NE(r.output.find("depthboard.h5: frame 1's depth host time is before 1970"), std::string::npos) << r.output;
  record(1'700'000'000'000'000'000, 1'700'000'000'000'000'000 + 2 * kDay);
  r = Info();
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
  EXPECT_NE(r.output.find("depthboard.h5: its host times span 172800 s, more than a day"), std::string::npos)
      << r.output;
}

TEST_F(DamagedSession, NotAnHdf5File) {
  fs::remove(Recording());
  WriteFile(Recording(), "plain text");
  const auto r = Info();
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.output.find("depthboard.h5: not an HDF5 file"), std::string::npos) << r.output;
}

// A recording cut short (a partial copy) is named unreadable with its size,
// not listed as an empty one "from ?" with 0 frames.
TEST_F(DamagedSession, FileCutShortIsNamedUnreadable) {
  fs::resize_file(Recording(), fs::file_size(Recording()) / 2);
  const auto r = Info();
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.output.find("depthboard.h5 (depthboard)\n  unreadable  "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("damaged or cut short, " + std::to_string(fs::file_size(Recording())) + " bytes"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("from ?"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("frames      0"), std::string::npos) << r.output;
}

// Issue 47: one byte changed in the superblock (its base address, under the
// checksum) hung every tool for over 10 minutes: the first open fails, the
// SWMR open made for a killed writer's file then retried the checksum 100
// times with growing sleeps. Now it is damage at once.
TEST_F(DamagedSession, OneDamagedSuperblockByteIsNamedUnreadableAtOnce) {
  {
    std::fstream file(Recording(), std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(16);
    file.put('\x5a');
  }
  const auto r = RunShell("timeout 60 " + (BinDir() / "session-info").string() + " " + (scratch_ / "s").string());
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
  EXPECT_NE(r.output.find("depthboard.h5 (depthboard)\n  unreadable  "), std::string::npos) << r.output;
}

TEST_F(DamagedSession, NewerRecordingSchemaVersion) {
  {
    H5::H5File file(Recording().string(), H5F_ACC_RDWR);
    const long long version = 99;
    file.openAttribute("schema_version").write(H5::PredType::NATIVE_LLONG, &version);
  }
  const auto r = Info();
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.output.find("schema version 99 is not understood"), std::string::npos) << r.output;
}

TEST_F(DamagedSession, MissingDataset) {
  {
    H5::H5File file(Recording().string(), H5F_ACC_RDWR);
    file.unlink("/depth/valid");
  }
  const auto r = Info();
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.output.find("missing dataset /depth/valid"), std::string::npos) << r.output;
}

TEST_F(DamagedSession, MissingAttribute) {
  {
    H5::H5File file(Recording().string(), H5F_ACC_RDWR);
    file.removeAttr("purpose");
  }
  const auto r = Info();
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.output.find("missing attribute 'purpose'"), std::string::npos) << r.output;
}

TEST_F(DamagedSession, NewerSessionSchemaVersion) {
  auto json = ToJson(ReadSessionManifest(scratch_ / "s"));
  json["schema_version"] = 7;
  WriteFile(scratch_ / "s" / "session.json", json.dump());
  const auto r = Info();
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.output.find("session schema version 7 is not understood"), std::string::npos) << r.output;
}

TEST_F(DamagedSession, UnknownManifestKey) {
  auto json = ToJson(ReadSessionManifest(scratch_ / "s"));
  json["optcs"] = "stock";
  WriteFile(scratch_ / "s" / "session.json", json.dump());
  const auto r = Info();
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.output.find("unknown key \"optcs\""), std::string::npos) << r.output;
}

// A golden-session copy whose depthboard recording has two runs of damaged
// bytes inside its frames (frames 4 to 6 unreadable or out of range).
fs::path DamagedGoldenSession(const fs::path& dir) {
  const fs::path session = dir / "s";
  fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", session);
  const fs::path recording = session / "depthboard.h5";
  std::fstream file(recording, std::ios::in | std::ios::out | std::ios::binary);
  const auto size = static_cast<double>(fs::file_size(recording));
  for (const double at : {0.4, 0.6}) {
    file.seekp(static_cast<std::streamoff>(at * size));
    const std::string damage(4096, '\xff');
    file.write(damage.data(), static_cast<std::streamsize>(damage.size()));
  }
  return session;
}

// Frames damaged inside a recording are skipped, and the summary says how
// many of those it skipped were unreadable.
TEST(DamagedFrames, AreSkippedAndCountedAsUnreadable) {
  ScratchDir scratch;
  const auto r = RunTool("run-pipeline", DamagedGoldenSession(scratch.path()).string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(" of them unreadable (a damaged recording?)"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("HDF5-DIAG"), std::string::npos) << r.output;
}

// HDF5's own error stack stays off the terminal when a frame is read on
// another thread than the one that opened the recording (the graph's
// workers): the library keeps its printing switch per thread.
TEST(DamagedFrames, ReadOnAnotherThreadPrintNoHdf5ErrorStack) {
  ScratchDir scratch;
  const RecordingReader reader(DamagedGoldenSession(scratch.path()) / "depthboard.h5");
  int unreadable = 0;
  ::testing::internal::CaptureStderr();
  std::thread worker([&] {
    for (std::int64_t i = 0; i < reader.frame_count(); ++i) {
      try {
        reader.ReadFrame(i);
      } catch (const std::exception&) {
        ++unreadable;
      }
    }
  });
  worker.join();
  const std::string printed = ::testing::internal::GetCapturedStderr();
  EXPECT_GT(unreadable, 0);
  EXPECT_EQ(printed.find("HDF5-DIAG"), std::string::npos) << printed.substr(0, 500);
}

}  // namespace
}  // namespace speckle
