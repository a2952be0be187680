#pragma once
// The model a run fits (run-pipeline --model FILE). Versioned like every file
// we read; stored in each calibration artifact.
#include <nlohmann/json.hpp>
#include <string>

#include "model/base_form.h"

namespace speckle {

inline constexpr int kModelSpecSchemaVersion = 1;

enum class UndistortionUse { kAuto, kOn, kOff };

struct ModelSpec {
  model::BaseForm base_form = model::BaseForm::kReciprocal;
  // auto: apply the undistortion grid when it lowers the held-out error.
  UndistortionUse undistortion = UndistortionUse::kAuto;
  double huber_raw = 0;  // > 0: robust (Huber) loss with this scale
};

ModelSpec ModelSpecFromJson(const nlohmann::json& json, const std::string& origin);  // throws InputError
nlohmann::json ToJson(const ModelSpec& spec);

}  // namespace speckle
