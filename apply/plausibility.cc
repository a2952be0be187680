#include "apply/plausibility.h"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <tuple>

#include "model/base_form.h"
#include "model/sensor_family.h"

namespace speckle::apply {
namespace {

using model::kDisparityImageWidth;
using model::kFamilyBaselineM;
using model::kMaxBaselineM;
using model::kMinBaselineM;

// The family's lenses, as focal lengths in image widths: stock colour and IR
// 0.81-0.93 (thesis App. A, Burrus, Herrera), behind a Nyko Zoom 0.52-0.58.
constexpr double kMinFocalWidths = 0.4, kMaxFocalWidths = 1.3;
constexpr double kMaxAspectDeparture = 0.1;  // square pixels: fy / fx within 1 +- 0.1
constexpr double kCentreMargin = 0.25;       // the principal point within the image's middle half
// A chessboard described as it is leaves a fraction of a pixel (0.06-0.5 px
// on the simulator and the real sets); a wrong square count leaves many.
constexpr double kMaxColourRmsPx = 2.0;
// An OpenNI driver's millimetres are millimetres to a few per cent.
constexpr double kMaxMillimetreScaleDeparture = 0.15;

double Number(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_number() ? it->get<double>() : NAN;
}

// What JoinProblems reads as "the views did not pin it down".
constexpr const char* kNotPinned = "the views do not pin it down";

// ", known only to +- S px: the views do not pin it down" when the fit's own
// sigma of term `term` is over a tenth of its value `value`; "" otherwise.
std::string LooselyKnown(const nlohmann::json& sigma, std::size_t term, double value) {
  if (!sigma.is_array() || sigma.size() <= term || !sigma[term].is_number()) return "";
  const double s = sigma[term].get<double>();
  return s > 0.1 * std::abs(value) ? fmt::format(", known only to ± {:.0f} px: {}", s, kNotPinned) : "";
}

void CheckCamera(const nlohmann::json& camera, const std::string& name, std::vector<std::string>& out) {
  if (!camera.is_object()) return;
  const double fx = Number(camera, "fx"), fy = Number(camera, "fy"), cx = Number(camera, "cx"),
               cy = Number(camera, "cy");
  const auto size = camera.value("image_size", nlohmann::json());
  if (!size.is_array() || size.size() != 2 || !size[0].is_number() || !size[1].is_number()) return;
  const double w = size[0].get<double>(), h = size[1].get<double>();
  const std::string where = "cameras." + name;
  const auto sigma = camera.value("stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3", nlohmann::json());
  for (const auto& [key, f, term] : {std::tuple{"fx", fx, 0}, std::tuple{"fy", fy, 1}})
    if (std::isfinite(f) && (f < kMinFocalWidths * w || f > kMaxFocalWidths * w))
      out.push_back(
          fmt::format("{}.{} {:.1f} px is {:.2f} image widths, and no lens of the family has one outside "
                      "{} to {} (stock about 0.81-0.93, behind a wide-angle adapter about 0.52-0.58){}",
                      where, key, f, f / w, kMinFocalWidths, kMaxFocalWidths, LooselyKnown(sigma, term, f)));
  if (std::isfinite(fx) && std::isfinite(fy) && fx > 0 && std::abs(fy / fx - 1) > kMaxAspectDeparture)
    out.push_back(fmt::format("{}: fy / fx is {:.3f}, and the family's pixels are square", where, fy / fx));
  if ((std::isfinite(cx) && std::abs(cx / w - 0.5) > kCentreMargin) ||
      (std::isfinite(cy) && std::abs(cy / h - 0.5) > kCentreMargin))
    out.push_back(
        fmt::format("{}: the principal point ({:.1f}, {:.1f}) px lies outside the middle half of its "
                    "{:.0f}x{:.0f} image",
                    where, cx, cy, w, h));
  // Fitted to views (given or nominal intrinsics have none): each of fx, fy,
  // cx, cy was measured, so a standard deviation of 0 says the fit was not.
  if (camera.value("views", 0) > 0 && sigma.is_array() && sigma.size() >= 4) {
    static constexpr std::array<const char*, 4> kNames = {"fx", "fy", "cx", "cy"};
    for (std::size_t i = 0; i < kNames.size(); ++i)
      if (!sigma[i].is_number() || !(sigma[i].get<double>() > 0) || !std::isfinite(sigma[i].get<double>())) {
        out.push_back(
            fmt::format("{}: the fitted {}'s standard deviation is {}: its covariance is singular, so "
                        "the fit did not measure it",
                        where, kNames[i], sigma[i].dump()));
        break;
      }
  }
  const double rms = Number(camera, "rms_reprojection_px");
  if (name == "colour" && camera.value("views", 0) > 0 && rms > kMaxColourRmsPx)
    out.push_back(
        fmt::format("{}: the chessboard fit leaves {:.1f} px rms, where a board as described leaves a "
                    "fraction of a pixel",
                    where, rms));
}

// The depth scale against the family's: the baseline the base form implies
// (11-bit raw), or the driver's millimetres (linear_mm). A wrong square size
// scales every depth, and this baseline alike.
void CheckDepthScale(const nlohmann::json& calibration, std::vector<std::string>& out) {
  const nlohmann::json& model = calibration.value("model", nlohmann::json::object());
  const nlohmann::json& parameters = model.value("parameters", nlohmann::json::array());
  if (!model.value("base_form", nlohmann::json()).is_string()) return;
  model::BaseForm form;
  try {
    form = model::BaseFormFromName(model["base_form"].get<std::string>());
  } catch (const std::exception&) {
    return;  // the readers name it
  }
  std::vector<double> base;
  for (const auto& p : parameters)
    if (p.is_object() && p.value("block", std::string()) == "base" && p.value("value", nlohmann::json()).is_number())
      base.push_back(p["value"].get<double>());
  if (base.size() != model::Info(form).parameters.size()) return;
  if (form == model::BaseForm::kLinearMm) {
    const double z = model::DepthFromRaw(form, base.data(), 1000.0);
    if (std::isfinite(z) && std::abs(z - 1) > kMaxMillimetreScaleDeparture)
      out.push_back(
          fmt::format("the base form gives {:.3f} m where the driver says 1000 mm: the depth scale comes "
                      "from the board's metric size, so every depth is likely {:.0f} % {}",
                      z, 100 * std::abs(z - 1), z < 1 ? "short" : "long"));
    return;
  }
  // The disparity is measured on the sensor's 640-wide depth image whatever
  // size the frames are delivered at, so fx is taken at that width.
  const nlohmann::json depth = calibration.value("cameras", nlohmann::json::object()).value("depth", nlohmann::json());
  const nlohmann::json size = depth.is_object() ? depth.value("image_size", nlohmann::json()) : nlohmann::json();
  if (!size.is_array() || size.empty() || !size[0].is_number() || !(size[0].get<double>() > 0)) return;
  const double fx = Number(depth, "fx") * kDisparityImageWidth / size[0].get<double>();
  const double near = model::RawFromDepth(form, base.data(), 1.0), far = model::RawFromDepth(form, base.data(), 2.0);
  const double baseline = (far - near) / (4 * fx);  // raw = c - 8 fx B / z, so 1 m to 2 m spans 4 fx B
  if (!std::isfinite(baseline) || !(fx > 0)) return;
  if (baseline < kMinBaselineM || baseline > kMaxBaselineM)
    out.push_back(fmt::format(
        "the base form (raw {:.0f} at 1 m, {:.0f} at 2 m) and the depth camera's fx {:.1f} px imply a projector "
        "{:.1f} cm from the IR camera, where every sensor of the family has about 7.5 cm: the depth scale comes "
        "from the board's metric size, so every depth is likely about {:.0f} % {}",
        near, far, fx, 100 * baseline, 100 * std::abs(baseline / kFamilyBaselineM - 1),
        baseline < kFamilyBaselineM ? "short" : "long"));
}

}  // namespace

std::vector<std::string> ImplausibleCalibration(const nlohmann::json& calibration) {
  std::vector<std::string> out;
  if (!calibration.is_object()) return out;
  const nlohmann::json& cameras = calibration.value("cameras", nlohmann::json::object());
  if (cameras.is_object()) {
    CheckCamera(cameras.value("colour", nlohmann::json()), "colour", out);
    CheckCamera(cameras.value("depth", nlohmann::json()), "depth", out);
  }
  CheckDepthScale(calibration, out);
  return out;
}

nlohmann::json PlausibilityJson(const std::vector<std::string>& problems, bool accepted) {
  return {{"problems", problems}, {"accepted", accepted && !problems.empty()}};
}

std::vector<std::string> UnacceptedProblems(const nlohmann::json& calibration) {
  std::vector<std::string> problems = ImplausibleCalibration(calibration);
  const nlohmann::json& stored = calibration.value("plausibility", nlohmann::json::object());
  if (stored.is_object() && stored.value("accepted", false)) problems.clear();
  return problems;
}

std::string JoinProblems(const std::vector<std::string>& problems) {
  std::string out;
  bool loose = false;
  for (std::size_t i = 0; i < problems.size(); ++i) {
    out += fmt::format("{}({}) {}", i ? "; " : "", i + 1, problems[i]);
    loose = loose || problems[i].find(kNotPinned) != std::string::npos;
  }
  const char* kBoard =
      "the board is described wrongly in session.json's rig: squares counts squares, not inner corners (a board of "
      "9 x 7 squares has 8 x 6 inner corners), and square_size_m is one square's side in metres";
  // A camera its views leave loose is likelier too few or too alike poses
  // than a wrong board (issue 47's probe: 12 poses of a board described
  // right were sent to check the board).
  if (loose)
    return out + fmt::format(
                     ". Most likely the board poses do not pin the camera down: too few, or too alike (record 15 "
                     "to 25, near to far, tilted up to 30 degrees, out to the image's corners); else {}",
                     kBoard);
  return out + ". Most likely " + kBoard;
}

}  // namespace speckle::apply
