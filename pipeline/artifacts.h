#pragma once
// A run's artifacts: a new immutable version directory under the session,
// calibrations/vNNNN/, holding calibration.json, report.json, samples.h5 (the
// paired samples, so a re-fit needs no detection) and undistortion_grid.h5.
// Written in a hidden temporary directory and renamed into place: a crash
// leaves no partial version, and earlier versions are never touched.
#include <filesystem>
#include <nlohmann/json.hpp>

#include "pipeline/calibration_run.h"

namespace speckle {

inline constexpr int kCalibrationSchemaVersion = 1;
inline constexpr int kReportSchemaVersion = 1;
inline constexpr int kSamplesSchemaVersion = 1;
inline constexpr int kGridSchemaVersion = 1;

nlohmann::json CalibrationJson(const CalibrationRun& run, const std::filesystem::path& session_dir);
nlohmann::json ReportJson(const CalibrationRun& run);

void WriteSamples(const std::filesystem::path& path, const std::vector<PairedSample>& samples);
std::vector<PairedSample> ReadSamples(const std::filesystem::path& path);  // throws InputError
void WriteGrid(const std::filesystem::path& path, const UndistortionGrid& grid);
UndistortionGrid ReadGrid(const std::filesystem::path& path);  // throws InputError

// Writes every artifact of `run` and returns the new version directory.
std::filesystem::path WriteCalibrationVersion(const std::filesystem::path& session_dir, const CalibrationRun& run);

// SHA-256 of a file, hex.
std::string Sha256File(const std::filesystem::path& path);

}  // namespace speckle
