#include "apply/depth_calibration.h"
#include "apply/depth_calibration_json.h"

#include <fmt/format.h>

#include <array>
#include <cmath>

#include "apply/plausibility.h"
#include "apply/undistortion_grid_file.h"
#include "model/depth_model.h"
#include "model/undistortion_grid.h"
#include "schemas/artifact_schema.h"
#include "schemas/json_fields.h"

namespace speckle::apply {
namespace {

namespace fs = std::filesystem;

PinholeCamera CameraFromJson(const nlohmann::json& json, const std::string& where) {
  JsonFields f(json, where);  // other keys (uncertainties, views) are the report's business
  PinholeCamera c;
  // Each side read as written: as an int, 4294967936 wrapped to 640.
  const auto size = f.Required<std::vector<nlohmann::json>>("image_size");
  // Read as an array of two, [640, 480, 3] lost its third value without a word.
  if (size.size() != 2)
    throw InputError(f.Path("image_size") + ": expected [width, height], found " + std::to_string(size.size()) +
                     " values");
  for (const nlohmann::json& side : size)
    if (!side.is_number_integer() || side.get<double>() < 1 || side.get<double>() > 100000)
      throw InputError(f.Path("image_size") + ": expected a width and height of 1 to 100000 pixels, found " +
                       side.dump());
  c.width = size[0].get<int>(), c.height = size[1].get<int>();
  c.fx = f.RequiredInRange("fx", 1, 1e5);
  c.fy = f.RequiredInRange("fy", 1, 1e5);
  // A principal point lies on the image; lens terms beyond +-100 describe no lens.
  c.cx = f.RequiredInRange("cx", 0, c.width);
  c.cy = f.RequiredInRange("cy", 0, c.height);
  c.distortion = f.Required<lens::Coefficients>("distortion_k1_k2_p1_p2_k3");
  for (std::size_t i = 0; i < c.distortion.size(); ++i)
    if (!std::isfinite(c.distortion[i]) || std::abs(c.distortion[i]) > 100)
      throw InputError(f.Path("distortion_k1_k2_p1_p2_k3") + "[" + std::to_string(i) +
                       "]: expected a finite lens coefficient within +-100, found " + std::to_string(c.distortion[i]));
  return c;
}

// The base form must map the depths a Kinect sees (kCheckedNearM to
// kCheckedFarM) to finite raw values at least a raw unit apart, and back to
// positive finite depths: a = b = 0 or a = 1e308 give no depth at all.
constexpr double kCheckedNearM = 0.5, kCheckedFarM = 5.0;
// No rig of a depth and a colour camera of this family is a metre apart.
constexpr double kMaxExtrinsicsTranslationM = 1.0;

std::string DepthRangeProblem(const model::DepthModel& m) {
  const model::BaseForm form = m.Definition().form;
  const double* p = m.Base().data();
  const double r_near = model::RawFromDepth(form, p, kCheckedNearM), r_far = model::RawFromDepth(form, p, kCheckedFarM);
  const std::string range = std::to_string(kCheckedNearM) + " to " + std::to_string(kCheckedFarM) + " m";
  if (!std::isfinite(r_near) || !std::isfinite(r_far) || std::abs(r_far - r_near) < 1)
    return "the base form maps " + range + " to no usable raw range (raw " + std::to_string(r_near) + " to " +
           std::to_string(r_far) + ")";
  // Raw values a sensor can send: a model that puts the depths at negative
  // raw values passes the round trip but gives no depth for any real frame
  // (apply-calibration wrote empty clouds with exit 0).
  const double raw_max = form == model::BaseForm::kLinearMm ? 65535 : 2047;
  if (std::min(r_near, r_far) < 0 || std::max(r_near, r_far) > raw_max)
    return fmt::format(
        "the base form puts {} at raw {:.0f} to {:.0f}, outside the raw values a sensor sends (0 to "
        "{:.0f}): no real frame would get a depth",
        range, r_near, r_far, raw_max);
  for (double t : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const double raw = r_near + t * (r_far - r_near);
    const double z = model::DepthFromRaw(form, p, raw);
    if (!std::isfinite(z) || z <= 0)
      return "the base form gives depth " + std::to_string(z) + " m at raw " + std::to_string(raw) +
             ", expected a positive depth over the raw range of " + range;
  }
  return {};
}

std::shared_ptr<const model::DepthModel> ModelFromJson(const nlohmann::json& json, const std::string& where) {
  JsonFields f(json, where);
  model::ModelDefinition definition;
  definition.form = model::BaseFormFromName(f.Required<std::string>("base_form"));
  const nlohmann::json& effects = f.RequiredValue("effects");
  if (!effects.is_array()) throw InputError(f.Path("effects") + ": expected an array");
  for (std::size_t k = 0; k < effects.size(); ++k)
    definition.effects.push_back(
        model::EffectSpecFromJson(effects[k], f.Path("effects") + "[" + std::to_string(k) + "]"));
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
    if (!std::isfinite(values.back()) || std::abs(values.back()) > 1e12)
      throw InputError(p.Path("value") + ": expected a finite value within +-1e12, found " +
                       std::to_string(values.back()));
  }
  model->SetFlat(values);
  if (const std::string problem = DepthRangeProblem(*model); !problem.empty())
    throw InputError(f.Path("parameters") + ": " + problem);
  return model;
}

}  // namespace

DepthCalibration LoadDepthCalibration(const fs::path& path) {
  const fs::path file = fs::is_directory(path) ? path / "calibration.json" : path;
  return DepthCalibrationFromJson(ReadArtifactJson(file, "speckle.calibration", kCalibrationSchemaVersion, 2), file);
}

namespace {

// calibration.json's member `key` of `object` (at `where`), or an error
// naming it (nlohmann's own says "[json.exception.out_of_range.403] key
// 'model' not found").
const nlohmann::json& Member(const nlohmann::json& object, const std::string& key, const std::string& where) {
  if (!object.is_object()) throw InputError(where + ": expected an object, found " + JsonExcerpt(object));
  const auto it = object.find(key);
  if (it == object.end()) throw InputError(where + ": missing required key \"" + key + "\"");
  return *it;
}

}  // namespace

DepthCalibration DepthCalibrationFromJson(const nlohmann::json& j, const fs::path& file) {
  const std::string where = file.string();
  DepthCalibration c;
  c.file = file;
  try {
    const nlohmann::json& cameras = Member(j, "cameras", where);
    c.depth = CameraFromJson(Member(cameras, "depth", where + ": cameras"), where + ": cameras.depth");
    c.colour = CameraFromJson(Member(cameras, "colour", where + ": cameras"), where + ": cameras.colour");
    JsonFields extrinsics(Member(cameras, "depth_from_colour", where + ": cameras"),
                          where + ": cameras.depth_from_colour");
    const auto axis_angle = extrinsics.Required<std::vector<double>>("rotation_axis_angle_rad");
    const auto translation = extrinsics.Required<std::vector<double>>("translation_m");
    if (axis_angle.size() != 3 || translation.size() != 3)
      throw InputError(where +
                       ": cameras.depth_from_colour: expected 3 numbers in rotation_axis_angle_rad and "
                       "translation_m");
    const Eigen::Vector3d r(axis_angle[0], axis_angle[1], axis_angle[2]);
    // A rotation of no finite angle (1e308 about two axes) loses every
    // point's colour while applied.json still says "colour"; NaN fails both
    // comparisons; no rig is a metre apart either.
    const Eigen::Vector3d t(translation[0], translation[1], translation[2]);
    if (!(r.norm() <= 2 * M_PI) || !(t.norm() <= kMaxExtrinsicsTranslationM))
      throw InputError(
          fmt::format("{}: cameras.depth_from_colour is not a rig's (rotation {} {} {} rad, translation "
                      "{} {} {} m; a Kinect's cameras are centimetres apart)",
                      where, r.x(), r.y(), r.z(), t.x(), t.y(), t.z()));
    c.depth_from_colour.linear() =
        (r.norm() > 0 ? Eigen::AngleAxisd(r.norm(), r.normalized()) : Eigen::AngleAxisd::Identity()).toRotationMatrix();
    c.depth_from_colour.translation() = t;
    const nlohmann::json& model = Member(j, "model", where);
    c.model = ModelFromJson(model, where + ": model");
    if (const auto problems = UnacceptedProblems(j); !problems.empty())
      throw InputError(where + ": " + kNotOfTheFamily + ", so it is not used: " + JoinProblems(problems) +
                       " (for a sensor outside the family, run-pipeline --accept-implausible keeps such a result)");
    c.depth_units =
        c.model->Definition().form == model::BaseForm::kLinearMm ? DepthUnits::kMillimetre : DepthUnits::kRaw11Bit;
    if (Member(model, "undistortion", where + ": model").get<bool>()) {
      const nlohmann::json& grid = Member(j, "undistortion_grid", where);
      if (!grid.is_string())
        throw InputError(where + ": undistortion_grid: the model applies a grid but names no file");
      c.grid = std::make_shared<const UndistortionGrid>(ReadGrid(file.parent_path() / grid.get<std::string>()));
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(where + ": " + e.what());
  }
  return c;
}

}  // namespace speckle::apply
