#include "pipeline/model_spec.h"

#include "schemas/errors.h"
#include "schemas/json_fields.h"

namespace speckle {

ModelSpec ModelSpecFromJson(const nlohmann::json& json, const std::string& origin) {
  JsonFields f(json, origin);
  const int version = f.Optional<int>("schema_version", kModelSpecSchemaVersion);
  if (version != kModelSpecSchemaVersion) {
    throw SchemaVersionError(origin + ": model spec schema version " + std::to_string(version) +
                             " is not understood (this tool reads version " + std::to_string(kModelSpecSchemaVersion) + ")");
  }
  ModelSpec spec;
  try {
    spec.base_form = model::BaseFormFromName(f.Optional<std::string>("base_form", "reciprocal"));
  } catch (const InputError& e) {
    throw InputError(f.Path("base_form") + ": " + e.what());
  }
  const std::string undistortion = f.Optional<std::string>("undistortion", "auto");
  if (undistortion == "auto") spec.undistortion = UndistortionUse::kAuto;
  else if (undistortion == "on") spec.undistortion = UndistortionUse::kOn;
  else if (undistortion == "off") spec.undistortion = UndistortionUse::kOff;
  else throw InputError(f.Path("undistortion") + ": expected auto, on or off, found \"" + undistortion + "\"");
  spec.huber_raw = f.OptionalInRange("huber_raw", 0, 0, 100);
  f.RejectUnknownKeys();
  return spec;
}

nlohmann::json ToJson(const ModelSpec& spec) {
  static constexpr const char* kUse[] = {"auto", "on", "off"};
  return {{"schema_version", kModelSpecSchemaVersion},
          {"base_form", model::Info(spec.base_form).name},
          {"undistortion", kUse[static_cast<int>(spec.undistortion)]},
          {"huber_raw", spec.huber_raw}};
}

}  // namespace speckle
