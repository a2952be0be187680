#include "lab/model_spec.h"

#include "model/effect.h"
#include "schemas/errors.h"
#include "schemas/json_fields.h"

namespace speckle {

ModelSpec ModelSpecFromJson(const nlohmann::json& json, const std::string& origin) {
  JsonFields f(json, origin);
  const int version = f.Optional<int>("schema_version", kModelSpecSchemaVersion);
  if (version != 1 && version != kModelSpecSchemaVersion) {
    throw SchemaVersionError(origin + ": model spec schema version " + std::to_string(version) +
                             " is not understood (this tool reads version " + std::to_string(kModelSpecSchemaVersion) +
                             ")");
  }
  ModelSpec spec;
  try {
    spec.base_form = model::BaseFormFromName(f.Optional<std::string>("base_form", "reciprocal"));
  } catch (const InputError& e) {
    throw InputError(f.Path("base_form") + ": " + e.what());
  }
  const std::string undistortion = f.Optional<std::string>("undistortion", "auto");
  if (undistortion == "auto")
    spec.undistortion = UndistortionUse::kAuto;
  else if (undistortion == "on")
    spec.undistortion = UndistortionUse::kOn;
  else if (undistortion == "off")
    spec.undistortion = UndistortionUse::kOff;
  else
    throw InputError(f.Path("undistortion") + ": expected auto, on or off, found \"" + undistortion + "\"");
  spec.huber_raw = f.OptionalInRange("huber_raw", 0, 0, 100);
  const nlohmann::json effects = f.Optional<nlohmann::json>("effects", nlohmann::json::array());
  if (!effects.is_array()) throw InputError(f.Path("effects") + ": expected an array of effects");
  for (std::size_t i = 0; i < effects.size(); ++i) {
    const std::string where = f.Path("effects") + "[" + std::to_string(i) + "]";
    try {
      spec.effects.push_back(model::EffectSpecFromJson(effects[i], where));
    } catch (const SchemaVersionError&) {
      throw;
    } catch (const InputError& e) {
      const std::string what = e.what();
      throw InputError(what.rfind(where, 0) == 0 ? what : where + ": " + what);
    }
    for (std::size_t j = 0; j + 1 < spec.effects.size(); ++j) {
      if (spec.effects[j].name == spec.effects.back().name)
        throw InputError(where + ": effect \"" + spec.effects.back().name + "\" appears twice");
    }
  }
  f.RejectUnknownKeys();
  return spec;
}

nlohmann::json ToJson(const ModelSpec& spec) {
  static constexpr const char* kUse[] = {"auto", "on", "off"};
  nlohmann::json effects = nlohmann::json::array();
  for (const auto& e : spec.effects) effects.push_back(model::ToJson(e));
  return {{"schema_version", kModelSpecSchemaVersion},
          {"base_form", model::Info(spec.base_form).name},
          {"undistortion", kUse[static_cast<int>(spec.undistortion)]},
          {"huber_raw", spec.huber_raw},
          {"effects", effects}};
}

ModelSpec DefaultModelSpec(DepthUnits units) {
  ModelSpec spec;
  if (units == DepthUnits::kMillimetre) spec.base_form = model::BaseForm::kLinearMm;
  return spec;
}

void CheckModelUnits(const ModelSpec& spec, DepthUnits units, const std::string& origin) {
  const bool millimetre_form = spec.base_form == model::BaseForm::kLinearMm;
  if (millimetre_form != (units == DepthUnits::kMillimetre)) {
    throw InputError(origin + ": base_form " + model::Info(spec.base_form).name + " takes " +
                     (millimetre_form ? "millimetres" : "raw 11-bit disparities") + ", but the session's depth is " +
                     ToString(units) + "; use " + (millimetre_form ? "reciprocal, tangent or disparity" : "linear_mm"));
  }
  for (const auto& info : model::EffectCatalogue()) {
    if (info.AppliesTo(units == DepthUnits::kMillimetre)) continue;
    for (const auto& effect : spec.effects) {
      if (effect.formula || effect.name != info.name) continue;
      throw InputError(origin + ": the effect " + info.name + " is for " + info.units +
                       " sessions, but the session's depth is " + ToString(units));
    }
  }
}

}  // namespace speckle
