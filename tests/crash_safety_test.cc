// A recorder killed with SIGKILL leaves a session that opens and holds every
// frame up to its last flush, each identical to what the simulator rendered.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <thread>

#include "recorder/recording_reader.h"
#include "schemas/session_manifest.h"
#include "simulator/session_simulator.h"
#include "test_util.h"

namespace speckle {
namespace {

using namespace testing;

TEST(CrashSafety, KilledRecorderKeepsFlushedFrames) {
  ScratchDir dir;
  const fs::path scenario_file = dir / "scenario.json";
  const nlohmann::json scenario_json = {
      {"seed", 11}, {"depthboard", {{"poses", 200}, {"frames_per_pose", 2}}}, {"planar", {{"snapshots", 0}}}};
  std::ofstream(scenario_file) << scenario_json.dump();
  const fs::path session = dir / "s";

  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const std::string binary = (BinDir() / "record-session").string();
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
    execl(binary.c_str(), binary.c_str(), "sim", "--realtime", "--scenario", scenario_file.c_str(), "--out",
          session.c_str(), "--flush-interval-ms", "200", static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait until frames have been flushed (a frame takes about 0.4 MB: 3 MB is
  // several), then kill without warning. The deadline is long because under
  // AddressSanitizer on a busy machine the simulator renders a frame in seconds.
  const fs::path recording = session / "depthboard.h5";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(240);
  while (std::chrono::steady_clock::now() < deadline &&
         (!fs::exists(recording) || fs::file_size(recording) < 3'000'000)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the recorder finished before it could be killed";

  const RecordingReader reader(recording);
  EXPECT_FALSE(reader.closed_cleanly());
  ASSERT_GE(reader.frame_count(), 3) << "flushed frames were lost";
  EXPECT_LT(reader.frame_count(), 400);
  const sim::SessionSimulator simulator(sim::ScenarioFromJson(scenario_json, "test"));
  const auto& specs = simulator.Frames(sim::SimRecording::kDepthboard);
  // The first frames and the last one flushed, not all of them: under
  // AddressSanitizer each frame takes seconds to render again, and the CI run
  // of 2026-11-26 hit the test's 300 s limit comparing every frame.
  for (const std::int64_t i : {std::int64_t{0}, std::int64_t{1}, reader.frame_count() - 1}) {
    const FramePair frame = reader.ReadFrame(i);
    const sim::SimFrame expected = simulator.Render(sim::SimRecording::kDepthboard, specs[i]);
    ASSERT_EQ(cv::norm(frame.depth.image, expected.raw_depth, cv::NORM_INF), 0) << "frame " << i;
    ASSERT_EQ(cv::norm(frame.colour.image, expected.colour_rgb, cv::NORM_INF), 0) << "frame " << i;
  }
  // The user is told what happened, and the session still lists the file.
  EXPECT_EQ(ReadSessionManifest(session).recordings.size(), 1u);
  const auto info = RunTool("session-info", session.string());
  EXPECT_EQ(info.exit_code, 3) << info.output;
  EXPECT_NE(info.output.find("did not close it"), std::string::npos) << info.output;
}

// A small tmpfs mounted for the test and unmounted after it (mounting needs
// root, as CI runs).
struct SmallDisk {
  fs::path at;
  bool mounted = false;
  explicit SmallDisk(const fs::path& where, int megabytes) : SmallDisk(where, std::to_string(megabytes) + "m") {}
  SmallDisk(const fs::path& where, const std::string& size) : at(where) {
    fs::create_directories(at);
    mounted = RunShell("mount -t tmpfs -o size=" + size + " tmpfs " + at.string()).exit_code == 0;
  }
  ~SmallDisk() {
    if (mounted) RunShell("umount " + at.string());
  }
};

// A disk that fills while the simulator records ends with exit 3 naming the
// recording and the full disk (it ended in SIGSEGV at exit: HDF5 1.10's
// shutdown closed again a file whose close had failed), with no HDF5 noise,
// whether the session is new (--out) or grows (--add-to).
TEST(CrashSafety, FullDiskEndsWithExit3NamingTheRecording) {
  ScratchDir dir;
  const SmallDisk disk(dir / "small", 4);
  if (!disk.mounted) GTEST_SKIP() << "needs root to mount a 4 MB tmpfs (CI runs as root)";
  std::ofstream(dir / "boards.json")
      << R"({"depthboard": {"poses": 2, "frames_per_pose": 1}, "planar": {"snapshots": 0}, "ir_chessboard": {"poses": 0}})";
  std::ofstream(dir / "many.json")
      << R"({"depthboard": {"poses": 0}, "planar": {"snapshots": 40}, "ir_chessboard": {"poses": 0}})";
  const fs::path session = disk.at / "s";
  const auto small =
      RunTool("record-session", "sim --scenario " + (dir / "boards.json").string() + " --out " + session.string());
  ASSERT_EQ(small.exit_code, 0) << small.output;
  for (const auto& [how, recording] : {std::pair{"--add-to " + session.string(), session / "planar.h5"},
                                       std::pair{"--out " + (disk.at / "t").string(), disk.at / "t" / "planar.h5"}}) {
    SCOPED_TRACE(how);
    const auto full = RunTool("record-session", "sim --scenario " + (dir / "many.json").string() + " " + how);
    EXPECT_EQ(full.exit_code, 3) << full.output;
    EXPECT_NE(full.output.find(recording.string()), std::string::npos) << full.output;
    EXPECT_NE(full.output.find("the disk is full"), std::string::npos) << full.output;
    EXPECT_EQ(full.output.find("filesystem error"), std::string::npos)
        << "libstdc++'s own prefix, after ours (\"file system: filesystem error:\"):\n"
        << full.output;
    EXPECT_EQ(full.output.find("close failed"), std::string::npos) << "HDF5's destructors printed:\n" << full.output;
    if (fs::exists(disk.at / "t")) {
      // What was recorded before the disk filled is read (issue 47's outside
      // probe: a file whose structure never reached the disk, or one frame
      // half-written, was unreadable).
      const auto kept = RunTool("session-info", (disk.at / "t").string());
      EXPECT_NE(kept.output.find("valid: yes"), std::string::npos) << kept.output;
      EXPECT_NE(kept.output.find("frames every dataset holds"), std::string::npos) << kept.output;
    }
    RunShell("rm -rf " + (disk.at / "t").string());
  }
  // The session as it was before the failed --add-to still opens.
  const auto info = RunTool("session-info", session.string());
  EXPECT_NE(info.output.find("depthboard"), std::string::npos) << info.output;
}

// The calibration's users fill a disk too: apply-calibration's exports and
// compare's maps ended as "internal error" (exit 1) with no word of the full
// disk (issue 47's outside probe). Now exit 3, naming the file and the full
// disk, and nothing is left on it.
TEST(CrashSafety, AFullDiskWhileExportingOrComparingEndsWithExit3) {
  ScratchDir dir;
  fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", dir / "s", fs::copy_options::recursive);
  const std::string session = (dir / "s").string();
  ASSERT_EQ(RunTool("run-pipeline", session).exit_code, 0);
  const auto expect_full = [&](const SmallDisk& disk, const CommandResult& r) {
    EXPECT_EQ(r.exit_code, 3) << r.output;
    EXPECT_NE(r.output.find(disk.at.string()), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("could not write"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
    EXPECT_TRUE(fs::is_empty(disk.at)) << "left on the disk: " << RunShell("ls -A " + disk.at.string()).output;
  };
  const SmallDisk exports(dir / "exports", "200k"), maps(dir / "maps", "24k");
  if (!exports.mounted || !maps.mounted) GTEST_SKIP() << "needs root to mount a tmpfs (CI runs as root)";
  expect_full(exports,
              RunTool("apply-calibration", session + " --recording planar --frames 0:6 --format pcd,ply,csv --out " +
                                               (exports.at / "out").string()));
  expect_full(maps, RunTool("compare", session + " " + session + " --out " + (maps.at / "cmp").string()));
}

}  // namespace
}  // namespace speckle
