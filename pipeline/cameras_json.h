#pragma once
// calibration.json's `cameras` read back: a refit that re-runs the joint
// calibration starts from the parent's cameras (schemas/calibration_format.md).
#include <nlohmann/json.hpp>

#include <string>

#include "stages/records.h"

namespace speckle {

// Throws InputError naming the field (`where` prefixes it) that is missing or not a number.
CameraCalibration CamerasFromJson(const nlohmann::json& cameras, const std::string& where);

}  // namespace speckle
