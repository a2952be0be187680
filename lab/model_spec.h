#pragma once
// The model a run fits (run-pipeline --model FILE). Versioned like every file
// we read; stored in each calibration artifact.
#include <nlohmann/json.hpp>
#include <string>

#include "model/depth_model.h"
#include "schemas/session_manifest.h"

namespace speckle {

inline constexpr int kModelSpecSchemaVersion = 2;  // 2: effects (version 1 still read)

enum class UndistortionUse { kAuto, kOn, kOff };

struct ModelSpec {
  model::BaseForm base_form = model::BaseForm::kReciprocal;
  // auto: apply the undistortion grid when it lowers the held-out error.
  UndistortionUse undistortion = UndistortionUse::kAuto;
  double huber_raw = 0;  // > 0: robust (Huber) loss with this scale
  // Compiled effects by name, or objects: {"name", "frozen", "initial"} or a
  // formula effect {"name", "formula", "parameters", "doc"}.
  std::vector<model::EffectSpec> effects;

  model::ModelDefinition Definition() const { return {base_form, effects}; }
};

ModelSpec ModelSpecFromJson(const nlohmann::json& json, const std::string& origin);  // throws InputError

// The default model for a session's depth units: the reciprocal form for raw
// disparities, the linear form for a driver's millimetres (thesis App. C).
ModelSpec DefaultModelSpec(DepthUnits units);

// Throws InputError naming `origin` when the spec's base form does not take
// values in `units` (a disparity form on millimetres, or linear_mm on raw),
// or when one of its compiled effects is for the other units (kUnits, such
// as thermal_drift_mm).
void CheckModelUnits(const ModelSpec& spec, DepthUnits units, const std::string& origin);
nlohmann::json ToJson(const ModelSpec& spec);

}  // namespace speckle
