#pragma once
// A session's calibration versions: calibrations/v0001, v0002, ... Every tool
// lists, picks and numbers them here, so they agree on what a version is.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace speckle {

inline constexpr std::int64_t kMaxCalibrationVersion = 99'999'999;

// The session's version folders, oldest first. Folders that only look like
// one (v99999999999) are named in a warning and left out.
std::vector<std::filesystem::path> CalibrationVersions(const std::filesystem::path& session_dir);

// The newest version; InputError naming the session when there is none, with
// `hint` saying what to do (e.g. "run run-pipeline first"). A version its
// writer flagged as no sensor of the family's (calibration.json's
// "plausibility", not accepted) is passed by, said, unless it is the only one.
std::filesystem::path NewestCalibrationVersion(const std::filesystem::path& session_dir, const std::string& hint);

// Renames the complete folder `staging` (inside calibrations/) to the next
// free version number and returns it. A concurrent run that takes a number
// first makes the rename fail, and the one after is tried.
std::filesystem::path PublishCalibrationVersion(const std::filesystem::path& session_dir,
                                                const std::filesystem::path& staging);

}  // namespace speckle
