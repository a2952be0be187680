#pragma once
// Output paths and the staging folders the tools write into before renaming:
// `.NAME.partial-PID-N` beside an output, `.incoming-PID-N` in calibrations/.
// The PID in the name says which process owns a staging folder, so the next
// run can tell a leftover of a killed process (SIGKILL, power cut) from the
// work of one still running, and remove it.
#include <filesystem>
#include <string>
#include <vector>

namespace speckle {

// A `--out`-style directory argument made plain: trailing slashes and "." /
// ".." steps removed. InputError (naming `flag`) for an empty value or one
// that names no new directory ("/", ".", "..").
std::filesystem::path NormalizeOutPath(const std::string& value, const std::string& flag);

// A fresh staging path for `target`: parent/.NAME.partial-PID-N.
std::filesystem::path PartialPathFor(const std::filesystem::path& target);
// A fresh staging folder name inside `dir` for a calibration version: .incoming-PID-N.
std::filesystem::path IncomingPathIn(const std::filesystem::path& dir);

// Removes the staging folders and files in `dir` whose owning process is no
// longer running and returns one line per removal (or per leftover that could
// not be removed), for the caller to log. Staging of running processes is left.
std::vector<std::string> RemoveStaleStaging(const std::filesystem::path& dir);

// Throws InputError when `path` (or any folder between `session_dir` and it)
// is a symbolic link: no tool writes outside the session through a link.
void RefuseSymlinkInside(const std::filesystem::path& session_dir, const std::filesystem::path& path);

}  // namespace speckle
