#pragma once
// What an effect may see of one sample besides its parameters. The names
// below are also the variables a formula effect can use and the axes the
// diagnostics plot residuals against. Adding one: the recipe at the top of
// lab/diagnosis/covariate_axes.h.
#include <array>
#include <string>

namespace speckle::model {

struct Covariates {
  double raw = 0;                         // measured raw value (after the undistortion grid, when used)
  double u = 0, v = 0;                    // depth pixel
  double x = 0, y = 0;                    // normalized undistorted depth coordinates
  double time_s = 0;                      // since the recording started
  double tilt_deg = 0;                    // board normal vs the depth axis
  double gradient_u = 0, gradient_v = 0;  // local raw gradient, raw units per pixel
  double velocity_u = 0, velocity_v = 0;  // board image velocity, colour pixels per second
  double albedo = 0.5;                    // 0 dark square, 1 light, 0.5 corner
  // How fast the board point's raw value changes (raw units per second,
  // from the neighbouring depth frames); 0 when applying a calibration, which
  // assumes a still scene.
  double raw_rate = 0;
};

struct CovariateField {
  const char* name;
  double Covariates::*field;
  // Its usual range, centre +- spread: where a formula's linearity and
  // finiteness are checked (CompiledFormula::DrawCovariates).
  double centre, spread;
};

inline constexpr std::array<CovariateField, 13> kCovariateFields{{
    {"raw", &Covariates::raw, 700, 300},
    {"u", &Covariates::u, 320, 320},
    {"v", &Covariates::v, 240, 240},
    {"x", &Covariates::x, 0, 0.6},
    {"y", &Covariates::y, 0, 0.45},
    {"time_s", &Covariates::time_s, 500, 500},
    {"tilt_deg", &Covariates::tilt_deg, 0, 30},
    {"gradient_u", &Covariates::gradient_u, 0, 20},
    {"gradient_v", &Covariates::gradient_v, 0, 20},
    {"velocity_u", &Covariates::velocity_u, 0, 500},
    {"velocity_v", &Covariates::velocity_v, 0, 500},
    {"albedo", &Covariates::albedo, 0.5, 0.5},
    {"raw_rate", &Covariates::raw_rate, 0, 20},
}};

}  // namespace speckle::model
