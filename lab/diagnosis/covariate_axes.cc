#include "lab/diagnosis/covariate_axes.h"

#include <cmath>

namespace speckle {

namespace {

using S = const PairedSample&;

// One line an axis (the recipe is in covariate_axes.h).
const std::vector<CovariateAxis> kCovariateAxes = {
    {"raw",
     "raw",
     [](S s) { return s.raw; },
     nullptr,
     {"raw"},
     {"raw_step", "height * (raw > {level})", {{"height", "raw"}}},
     true},
    {"depth",
     "m",
     [](S s) { return s.depth_m; },
     nullptr,
     {"raw"},
     {"raw_step", "height * (raw > {level})", {{"height", "raw"}}},
     true},
    {"image radius",
     "1",
     [](S s) { return std::hypot(s.x, s.y); },
     nullptr,
     {"x", "y"},
     {"radial", "k * (x^2 + y^2)", {{"k", "raw"}}}},
    {"image x", "1", [](S s) { return s.x; }, nullptr, {"x", "u"}, {"ramp_x", "k * x", {{"k", "raw"}}}},
    {"image y", "1", [](S s) { return s.y; }, nullptr, {"y", "v"}, {"ramp_y", "k * y", {{"k", "raw"}}}},
    {"image position",
     "px",
     [](S s) { return s.u; },
     [](S s) { return s.v; },
     {"x", "y", "u", "v"},
     {"image_ramp", "kx * x + ky * y", {{"kx", "raw"}, {"ky", "raw"}}}},
    {"time",
     "s",
     [](S s) { return s.time_s; },
     nullptr,
     {"time_s"},
     {"time_ramp", "k * time_s", {{"k", "raw/s"}}},
     true},
    {"board tilt",
     "deg",
     [](S s) { return s.tilt_deg; },
     nullptr,
     {"tilt_deg"},
     {"tilt_offset", "k * tilt_deg", {{"k", "raw/deg"}}}},
    {"depth gradient",
     "raw/px",
     [](S s) { return std::hypot(s.gradient_u, s.gradient_v); },
     nullptr,
     {"gradient_u", "gradient_v"},
     {"gradient_offset", "k * gradient_u", {{"k", "px"}}}},
    {"gradient along u",
     "raw/px",
     [](S s) { return s.gradient_u; },
     nullptr,
     {"gradient_u"},
     {"gradient_offset", "k * gradient_u", {{"k", "px"}}}},
    {"gradient along v",
     "raw/px",
     [](S s) { return s.gradient_v; },
     nullptr,
     {"gradient_v"},
     {"gradient_offset", "k * gradient_v", {{"k", "px"}}}},
    {"raw change with motion",
     "raw/s",
     [](S s) { return s.raw_rate; },
     nullptr,
     {"raw_rate"},
     {"rate_offset", "k * raw_rate", {{"k", "s"}}}},
    {"albedo",
     "1",
     [](S s) { return s.albedo; },
     nullptr,
     {"albedo"},
     {"albedo_offset", "k * (albedo - 0.5)", {{"k", "raw"}}}},
};

}  // namespace

const std::vector<CovariateAxis>& CovariateAxes() { return kCovariateAxes; }

const CovariateAxis* FindCovariateAxis(const std::string& name) {
  for (const auto& axis : CovariateAxes())
    if (name == axis.name) return &axis;
  return nullptr;
}

}  // namespace speckle
