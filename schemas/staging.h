#pragma once
// Output paths and the staging folders the tools write into before renaming:
// `.NAME.partial-PID-N` beside an output, `.incoming-PID-N` in calibrations/.
// The PID in the name says which process owns a staging folder, so the next
// run can tell a leftover of a killed process (SIGKILL, power cut) from the
// work of one still running, and remove it. Staging sits beside the user's own
// files (`--out` may be any folder), so a name alone never marks a leftover as
// ours: a staging folder holds a marker file naming its process, and a staged
// file is an HDF5 recording.
#include <filesystem>
#include <string>

namespace speckle {

// A `--out`-style directory argument made plain: trailing slashes and "." /
// ".." steps removed. InputError (naming `flag`) for an empty value or one
// that names no new directory ("/", ".", "..").
std::filesystem::path NormalizeOutPath(const std::string& value, const std::string& flag);

// A fresh staging path for `target`: parent/.NAME.partial-PID-N.
std::filesystem::path PartialPathFor(const std::filesystem::path& target);
// A fresh staging folder name inside `dir` for a calibration version: .incoming-PID-N.
std::filesystem::path IncomingPathIn(const std::filesystem::path& dir);

// The marker file inside every staging folder while it is being filled.
inline constexpr const char* kStagingMarker = ".speckle-staging";
// Creates the staging folder `staging` (which must not exist) with its marker.
void CreateStagingFolder(const std::filesystem::path& staging);
// Removes the marker again, just before the folder is renamed into place.
void RemoveStagingMarker(const std::filesystem::path& staging);

// Removes the staging leftovers in `dir`: entries named exactly as
// PartialPathFor / IncomingPathIn name them, whose process is no longer
// running, and which are ours (a folder with its marker naming that process, or
// a regular file that is an HDF5 file). Each removal is logged (a warning)
// before it is made, and so is each leftover that could not be removed.
void RemoveStaleStaging(const std::filesystem::path& dir);

// Throws InputError when `path` (or any folder between `session_dir` and it)
// is a symbolic link: no tool writes outside the session through a link.
void RefuseSymlinkInside(const std::filesystem::path& session_dir, const std::filesystem::path& path);

}  // namespace speckle
