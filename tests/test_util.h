#pragma once
// Shared test helpers: scratch directories, the real data in ../shared/data,
// and running the command-line tools as a user would.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

namespace speckle::testing {

namespace fs = std::filesystem;

inline fs::path SharedData() { return fs::path(SPECKLE_SHARED_DATA); }
inline fs::path BinDir() { return fs::path(SPECKLE_BIN_DIR); }

class ScratchDir {
 public:
  ScratchDir() {
    std::random_device entropy;
    path_ = fs::temp_directory_path() / ("speckle-test-" + std::to_string(entropy()));
    fs::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }
  fs::path operator/(const std::string& name) const { return path_ / name; }

 private:
  fs::path path_;
};

inline nlohmann::json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// The held-out raw RMS of a report's fit by its name ("reciprocal +undistortion"); 0 when absent.
inline double FitHeldOutRaw(const nlohmann::json& report, const std::string& name) {
  for (const auto& f : report["fits"])
    if (f["name"] == name && f["held_out_raw"].is_object() && f["held_out_raw"]["rms"].is_number())
      return f["held_out_raw"]["rms"];
  return std::numeric_limits<double>::quiet_NaN();  // no such fit: every comparison with it fails
}

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs a shell command line, its stderr with its stdout.
inline CommandResult RunShell(const std::string& command_line) {
  const std::string command = command_line + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  char buffer[4096];
  while (pipe && fgets(buffer, sizeof buffer, pipe)) result.output += buffer;
  const int status = pipe ? pclose(pipe) : -1;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// Runs `tool`, a binary in the build directory, with arguments.
inline CommandResult RunTool(const std::string& tool, const std::string& arguments) {
  return RunShell((BinDir() / tool).string() + " " + arguments);
}

// Copies the golden session to DIR/s and calibrates it with run-pipeline (2
// s: reciprocal + undistortion grid); returns the version it wrote. The grid
// is forced on: the apply tests load and fold one, and on this small session
// the automatic choice leaves it out.
inline fs::path CalibratedGoldenSession(const fs::path& dir) {
  fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", dir / "s", fs::copy_options::recursive);
  std::ofstream(dir / "grid_on.json")
      << R"({"schema_version": 2, "base_form": "reciprocal", "undistortion": "on", "effects": []})";
  const CommandResult run =
      RunTool("run-pipeline", (dir / "s").string() + " --model " + (dir / "grid_on.json").string());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  return dir / "s" / "calibrations" / "v0001";
}

// A suite whose tests share one calibrated golden session (its v0001 is
// Version()), made once for the suite.
class CalibratedGoldenSuite : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scratch_ = new ScratchDir;
    CalibratedGoldenSession(scratch_->path());
  }
  static void TearDownTestSuite() { delete scratch_; }
  static fs::path Version() { return *scratch_ / "s" / "calibrations" / "v0001"; }
  static inline ScratchDir* scratch_ = nullptr;
};

// True when `dir` holds nothing but `allowed` (used to prove that a failed
// import left no partial session behind).
inline bool OnlyHolds(const fs::path& dir, const std::vector<std::string>& allowed) {
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (std::find(allowed.begin(), allowed.end(), entry.path().filename().string()) == allowed.end()) return false;
  }
  return true;
}

}  // namespace speckle::testing
