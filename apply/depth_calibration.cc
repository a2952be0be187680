#include "apply/depth_calibration.h"

#include <array>

#include "apply/undistortion_grid_file.h"
#include "schemas/artifact_schema.h"
#include "schemas/json_fields.h"

namespace speckle::apply {
namespace {

namespace fs = std::filesystem;

PinholeCamera CameraFromJson(const nlohmann::json& json, const std::string& where) {
  JsonFields f(json, where);  // other keys (uncertainties, views) are the report's business
  PinholeCamera c;
  const auto size = f.Required<std::array<int, 2>>("image_size");
  c.width = size[0], c.height = size[1];
  if (c.width <= 0 || c.height <= 0) throw InputError(f.Path("image_size") + ": expected a positive width and height");
  c.fx = f.RequiredInRange("fx", 1, 1e5);
  c.fy = f.RequiredInRange("fy", 1, 1e5);
  c.cx = f.Required<double>("cx");
  c.cy = f.Required<double>("cy");
  c.distortion = f.Required<lens::Coefficients>("distortion_k1_k2_p1_p2_k3");
  return c;
}

std::shared_ptr<const model::DepthModel> ModelFromJson(const nlohmann::json& json, const std::string& where) {
  JsonFields f(json, where);
  model::ModelDefinition definition;
  definition.form = model::BaseFormFromName(f.Required<std::string>("base_form"));
  const nlohmann::json& effects = f.RequiredValue("effects");
  if (!effects.is_array()) throw InputError(f.Path("effects") + ": expected an array");
  for (std::size_t k = 0; k < effects.size(); ++k)
    definition.effects.push_back(model::EffectSpecFromJson(effects[k], f.Path("effects") + "[" + std::to_string(k) + "]"));
  auto model = std::make_shared<model::DepthModel>(definition);
  const nlohmann::json& parameters = f.RequiredValue("parameters");
  const auto names = model->FlatNames();
  if (!parameters.is_array() || parameters.size() != names.size()) {
    // Most likely written by a build whose effects had other parameters
    // (disparity_pattern's grid grew from 16 x 12 to 22 x 16).
    throw InputError(f.Path("parameters") + ": expected " + std::to_string(names.size()) + " parameters for " +
                     definition.Describe() + ", found " +
                     std::to_string(parameters.is_array() ? parameters.size() : 0) +
                     " (written by a build whose effects have other parameters? refit the session with this build)");
  }
  std::vector<double> values;
  for (std::size_t i = 0; i < names.size(); ++i) {
    JsonFields p(parameters[i], f.Path("parameters") + "[" + std::to_string(i) + "]");
    const std::string block = p.Required<std::string>("block"), name = p.Required<std::string>("name");
    if (block != names[i].block || name != names[i].name) {
      throw InputError(p.Path("name") + ": expected " + names[i].block + "." + names[i].name + ", found " + block +
                       "." + name);
    }
    values.push_back(p.Required<double>("value"));
  }
  model->SetFlat(values);
  return model;
}

}  // namespace

DepthCalibration LoadDepthCalibration(const fs::path& path) {
  const fs::path file = fs::is_directory(path) ? path / "calibration.json" : path;
  const nlohmann::json j = ReadArtifactJson(file, "speckle.calibration", kCalibrationSchemaVersion, 2);
  const std::string where = file.string();
  DepthCalibration c;
  c.file = file;
  try {
    const nlohmann::json& cameras = j.at("cameras");
    c.depth = CameraFromJson(cameras.at("depth"), where + ": cameras.depth");
    c.colour = CameraFromJson(cameras.at("colour"), where + ": cameras.colour");
    const nlohmann::json& extrinsics = cameras.at("depth_from_colour");
    const auto axis_angle = extrinsics.at("rotation_axis_angle_rad").get<std::array<double, 3>>();
    const auto translation = extrinsics.at("translation_m").get<std::array<double, 3>>();
    const Eigen::Vector3d r(axis_angle[0], axis_angle[1], axis_angle[2]);
    c.depth_from_colour.linear() = (r.norm() > 0 ? Eigen::AngleAxisd(r.norm(), r.normalized()) : Eigen::AngleAxisd::Identity()).toRotationMatrix();
    c.depth_from_colour.translation() = Eigen::Vector3d(translation[0], translation[1], translation[2]);
    c.model = ModelFromJson(j.at("model"), where + ": model");
    c.depth_units = c.model->Definition().form == model::BaseForm::kLinearMm ? DepthUnits::kMillimetre
                                                                             : DepthUnits::kRaw11Bit;
    if (j.at("model").at("undistortion").get<bool>()) {
      const nlohmann::json& grid = j.at("undistortion_grid");
      if (!grid.is_string()) throw InputError(where + ": undistortion_grid: the model applies a grid but names no file");
      c.grid = ReadGrid(file.parent_path() / grid.get<std::string>());
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(where + ": " + e.what());
  }
  return c;
}

}  // namespace speckle::apply
