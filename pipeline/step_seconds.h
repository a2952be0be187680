#pragma once
// Where a run's time went after the graph, for report.json (`step_seconds`)
// and the summary's last line: every fit and its parts, the diagnosis and
// each candidate, the camera perturbations and the wall hold-outs.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "pipeline/calibration_run.h"

namespace speckle {

// The model lab's part: `fits[]`, `diagnosis`, `model_lab` (fits and diagnosis).
nlohmann::json ModelStepSecondsJson(const ModelLab& lab);
// run-pipeline's part: `graph`, `camera_perturbations`, `wall_hold_outs`, `total`.
nlohmann::json RunStepSecondsJson(const CalibrationRun& run);

// "time         8.3 s: graph 1.2 s, fits 3.1 s, ..." (graph_seconds: none for a refit).
std::string StepSecondsLine(const ModelLab& lab, double total_seconds, std::optional<double> graph_seconds,
                            std::optional<double> perturbation_seconds, std::optional<double> wall_seconds,
                            std::optional<double> reading_seconds);

}  // namespace speckle
