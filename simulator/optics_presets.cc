#include "simulator/optics_presets.h"

#include "schemas/errors.h"

namespace speckle::sim {
namespace {

Eigen::Isometry3d ColourFromIr() {
  // The colour camera sits ~2.5 cm beside the IR camera, optical axes parallel.
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(-0.025, 0, 0);
  return t;
}

}  // namespace

SensorOptics StockOptics() {
  SensorOptics o;
  o.name = "stock";
  o.colour = {{640, 480}, 520.38, 520.19, 319.25, 261.87, {0.23026, -0.73952, 0.00085105, -0.0015311, 0.81742}};
  o.ir = {{640, 480}, 588.92, 587.89, 315.10, 252.12, {-0.089552, 0.47946, 0.0040476, 0.0045308, -0.80428}};
  o.colour_from_ir = ColourFromIr();
  return o;
}

SensorOptics WideAngleOptics() {
  SensorOptics o;
  o.name = "wide_angle";
  o.colour = {{640, 480}, 330.21, 329.69, 315.41, 261.00, {-0.12265, -0.032653, 0.00025016, -0.0039020, 0.017380}};
  o.ir = {{640, 480}, 373.35, 372.83, 324.78, 237.21, {-0.24012, 0.10622, -0.0058166, 0.0015052, -0.033573}};
  o.colour_from_ir = ColourFromIr();
  o.usable_radius = 0.95;  // the adapter vignettes the speckle pattern in the corners
  return o;
}

SensorOptics OpticsByName(const std::string& name) {
  if (name == "stock") return StockOptics();
  if (name == "wide_angle") return WideAngleOptics();
  throw InputError("unknown optics \"" + name + "\" (expected stock or wide_angle)");
}

}  // namespace speckle::sim
