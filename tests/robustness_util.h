#pragma once
// What the robustness tests share: a message that names what it must, a
// process that is certainly gone, and the staging a killed tool leaves.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "schemas/atomic_folder.h"
#include "schemas/staging.h"
#include "test_util.h"

namespace speckle::testing {

inline void ExpectNamed(const CommandResult& r, int exit_code, const std::string& names) {
  EXPECT_EQ(r.exit_code, exit_code) << r.output;
  EXPECT_NE(r.output.find(names), std::string::npos) << "message should name \"" << names << "\":\n" << r.output;
}

// A process id that is certainly not running: a child that has exited.
inline pid_t DeadPid() {
  const pid_t child = fork();
  if (child == 0) _exit(0);
  waitpid(child, nullptr, 0);
  return child;
}

// What a tool killed while writing leaves in `dir`: the real writer's staging
// folder (an output `a` beside --out, or a version in calibrations/), stopped
// mid-write in a child process that then exits as SIGKILL would leave it.
inline fs::path LeftoverOfADeadTool(const fs::path& dir, bool incoming = false) {
  fs::create_directories(dir);
  const pid_t child = fork();
  if (child == 0) {
    WriteFolderAside(
        incoming ? IncomingPathIn(dir) : PartialPathFor(dir / "a"),
        [](const fs::path& staging) {
          std::ofstream(staging / "calibration.json") << "{}";
          _exit(9);
        },
        [](const fs::path& staging) { return staging; });
    _exit(0);
  }
  waitpid(child, nullptr, 0);
  const std::string owner = "-" + std::to_string(child) + "-";
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().filename().string().find(owner) != std::string::npos) return entry.path();
  return {};
}

}  // namespace speckle::testing
