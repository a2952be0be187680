#pragma once
// Running another tool as a child process with its output in a log file:
// the fleet's units are whole run-pipeline runs, so that one unit's crash is
// that unit's failure and not the fleet's.
#include <filesystem>
#include <string>
#include <vector>

namespace speckle::fleet {

// argv[0] is looked up on PATH when it has no '/'. Returns the exit code, or
// 128 + the signal that ended it; throws std::runtime_error when it cannot start.
int RunLogged(const std::vector<std::string>& argv, const std::filesystem::path& log);

}  // namespace speckle::fleet
