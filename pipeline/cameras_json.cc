#include "pipeline/cameras_json.h"

#include <cmath>
#include <limits>

#include "schemas/errors.h"
#include "schemas/json_fields.h"

namespace speckle {
namespace {

constexpr const char* kCovarianceKey = "covariance_fx_fy_cx_cy_k1_k2_p1_p2_k3";

template <std::size_t N>
std::array<double, N> Numbers(const nlohmann::json& value, const std::string& where) {
  std::array<double, N> out{};
  if (!value.is_array() || value.size() != N)
    throw InputError(where + ": expected " + std::to_string(N) + " numbers, found " + JsonExcerpt(value));
  for (std::size_t i = 0; i < N; ++i) {
    if (!value[i].is_number() || !std::isfinite(value[i].get<double>()))
      throw InputError(where + "[" + std::to_string(i) + "]: expected a number, found " + JsonExcerpt(value[i]));
    out[i] = value[i].get<double>();
  }
  return out;
}

CameraIntrinsics CameraIntrinsicsFromJson(const nlohmann::json& json, const std::string& where) {
  JsonFields f(json, where);
  CameraIntrinsics c;
  const auto size = Numbers<2>(f.RequiredValue("image_size"), f.Path("image_size"));
  c.image_size = cv::Size(static_cast<int>(size[0]), static_cast<int>(size[1]));
  c.camera_matrix = cv::Matx33d(f.Required<double>("fx"), 0, f.Required<double>("cx"), 0, f.Required<double>("fy"),
                                f.Required<double>("cy"), 0, 0, 1);
  c.distortion = Numbers<5>(f.RequiredValue("distortion_k1_k2_p1_p2_k3"), f.Path("distortion_k1_k2_p1_p2_k3"));
  c.stddev =
      Numbers<9>(f.RequiredValue("stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3"), f.Path("stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3"));
  // Version 12 on; absent or null where the fit stated only the sigmas.
  if (const nlohmann::json* cov = f.OptionalValue(kCovarianceKey); cov && !cov->is_null()) {
    const auto values = Numbers<81>(*cov, f.Path(kCovarianceKey));
    c.covariance.assign(values.begin(), values.end());
  }
  const nlohmann::json* rms = f.OptionalValue("rms_reprojection_px");
  c.rms_reprojection_px = rms && rms->is_number() ? rms->get<double>() : 0;
  // Written since the first version; read back so that a refit's warnings count the views the cameras came from.
  const nlohmann::json* views = f.OptionalValue("views");
  c.views = views && views->is_number_integer() && views->get<long long>() >= 0 &&
                    views->get<long long>() <= std::numeric_limits<int>::max()
                ? views->get<int>()
                : 0;
  return c;
}

std::optional<double> OptionalNumber(const nlohmann::json& json, const std::string& key, const std::string& where) {
  if (!json.contains(key) || json[key].is_null()) return std::nullopt;
  if (!json[key].is_number())
    throw InputError(where + "." + key + ": expected a number or null, found " + JsonExcerpt(json[key]));
  return json[key].get<double>();
}

std::optional<JointAccount> JointFromJson(const nlohmann::json& json, const std::string& where) {
  if (json.is_null()) return std::nullopt;
  JointAccount account;
  JsonFields f(json, where);
  const nlohmann::json& terms = f.RequiredValue("terms");
  if (!terms.is_array() || terms.size() != 3)
    throw InputError(where + ".terms: expected 3 kinds of observation, found " + JsonExcerpt(terms));
  for (std::size_t i = 0; i < terms.size(); ++i) {
    JsonFields t(terms[i], where + ".terms[" + std::to_string(i) + "]");
    JointAccount::Term term{t.Required<std::string>("kind"), t.Required<std::string>("unit"),
                            t.Required<int>("observations")};
    // A kind with no observations has no scatter (null); its weight then reaches no residual.
    term.rms = term.observations == 0 && terms[i].value("rms", nlohmann::json()).is_null()
                   ? 1.0
                   : t.RequiredInRange("rms", 1e-6, 1e6);
    account.terms.push_back(term);
  }
  account.held = json.value("held", std::vector<std::string>{});
  return account;
}

}  // namespace

CameraCalibration CamerasFromJson(const nlohmann::json& cameras, const std::string& where) {
  try {
    CameraCalibration c;
    c.colour = CameraIntrinsicsFromJson(cameras.at("colour"), where + ".colour");
    c.depth = CameraIntrinsicsFromJson(cameras.at("depth"), where + ".depth");
    c.depth_intrinsics_source = cameras.value("depth_intrinsics_source", std::string());
    const nlohmann::json warning = cameras.value("depth_intrinsics_warning", nlohmann::json());
    if (warning.is_string()) c.depth_intrinsics_warning = warning.get<std::string>();
    c.depth_edge_offset_px = OptionalNumber(cameras, "depth_edge_offset_px", where);
    const nlohmann::json& e = cameras.at("depth_from_colour");
    const auto axis_angle =
        Numbers<3>(e.at("rotation_axis_angle_rad"), where + ".depth_from_colour.rotation_axis_angle_rad");
    const auto t = Numbers<3>(e.at("translation_m"), where + ".depth_from_colour.translation_m");
    const Eigen::Vector3d r(axis_angle[0], axis_angle[1], axis_angle[2]);
    c.depth_from_colour = Eigen::Isometry3d::Identity();
    if (r.norm() > 0) c.depth_from_colour.linear() = Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix();
    c.depth_from_colour.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
    if (e.contains("translation_sigma_m") && !e["translation_sigma_m"].is_null()) {
      const auto s = Numbers<3>(e["translation_sigma_m"], where + ".depth_from_colour.translation_sigma_m");
      c.extrinsics_translation_sigma_m = Eigen::Vector3d(s[0], s[1], s[2]);
    }
    c.extrinsics_rms_px = OptionalNumber(e, "outline_rms_px", where + ".depth_from_colour").value_or(0);
    c.depth_delay_s = OptionalNumber(e, "depth_delay_s", where + ".depth_from_colour");
    c.joint = JointFromJson(cameras.value("joint", nlohmann::json()), where + ".joint");
    return c;
  } catch (const nlohmann::json::exception& x) {
    throw InputError(where + ": " + x.what());
  }
}

}  // namespace speckle
