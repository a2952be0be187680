#pragma once
// What a refit costs as well as what it gains (issue 47): the new model's
// depth error bars against the parent's at every depth, and the camera
// warnings still in force, so that a model that cuts the held-out error but
// is known less well says so where the refit is printed.
#include <nlohmann/json.hpp>
#include <string>

#include "lab/model_lab.h"

namespace speckle {

// Lines for refit's summary: "depth sigma ..." as run-pipeline prints it, a
// line comparing it with the parent's report.json "depth_uncertainty" (when
// it has one), and the depth camera's warning when its cameras carry one.
std::string RefitCosts(const nlohmann::json& parent_report, const std::string& parent_name, const ModelLab& lab,
                       const CameraCalibration& cameras);

}  // namespace speckle
