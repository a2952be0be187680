#pragma once
// A run's artifacts: a new immutable version directory under the session,
// calibrations/vNNNN/, holding calibration.json, report.json, samples.h5 (the
// paired samples, so a re-fit needs no detection) and undistortion_grid.h5.
// Written in a hidden temporary directory and renamed into place: a crash
// leaves no partial version, and earlier versions are never touched.
#include <filesystem>
#include <nlohmann/json.hpp>

#include "pipeline/calibration_run.h"
#include "schemas/artifact_schema.h"

namespace speckle {

// The pipeline's parts of calibration.json and report.json; SetModelJson
// adds (or, for a refit, replaces) the model's parts.
nlohmann::json CalibrationJson(const CalibrationRun& run, const std::filesystem::path& session_dir);
nlohmann::json ReportJson(const CalibrationRun& run);
void SetModelJson(const ModelSpec& spec, const ModelLab& lab, nlohmann::json& calibration, nlohmann::json& report);

struct CachedSamples {
  std::vector<PairedSample> samples;
  DepthPerturbations perturbations;  // [camera input][sample]
};
void WriteSamples(const std::filesystem::path& path, const std::vector<PairedSample>& samples,
                  const DepthPerturbations& perturbations);
CachedSamples ReadSamples(const std::filesystem::path& path);  // throws InputError

struct VersionContent {
  nlohmann::json calibration, report;
  const std::vector<PairedSample>& samples;
  const DepthPerturbations& perturbations;
  const UndistortionGrid* grid = nullptr;
  nlohmann::json plots;  // PlotDataJson: goes into report.json and report.html
};
// Writes every artifact, with the session's history of versions added to the
// report, and returns the new version directory.
std::filesystem::path WriteCalibrationVersion(const std::filesystem::path& session_dir, VersionContent content);

// SHA-256 of a file, hex.
std::string Sha256File(const std::filesystem::path& path);

}  // namespace speckle
