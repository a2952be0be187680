#pragma once
// calibration.json and report.json as JSON: the pipeline's parts, and the
// model's parts that a refit replaces (formats: schemas/calibration_format.md).
#include <filesystem>
#include <nlohmann/json.hpp>

#include "pipeline/calibration_run.h"

namespace speckle {

// calibration.json's `cameras` (read back by pipeline/cameras_json.h).
nlohmann::json CamerasJson(const CameraCalibration& cameras);
// calibration.json's session.inputs: session.json and every recording, with
// their SHA-256, hashed before the run reads them.
nlohmann::json SessionInputsJson(const std::filesystem::path& session_dir);
nlohmann::json CalibrationJson(const CalibrationRun& run, const std::filesystem::path& session_dir,
                               const nlohmann::json& inputs);
nlohmann::json ReportJson(const CalibrationRun& run);
// Adds (or, for a refit, replaces) the model's parts of both.
void SetModelJson(const ModelSpec& spec, const ModelLab& lab, nlohmann::json& calibration, nlohmann::json& report);

}  // namespace speckle
