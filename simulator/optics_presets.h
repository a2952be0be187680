#pragma once
// Camera defaults from the source thesis, Appendix A (OpenCV calibrations of
// a Kinect at VGA): stock optics and the Nyko Zoom wide-angle adapter.
#include <Eigen/Geometry>
#include <string>

#include "simulator/camera_model.h"

namespace speckle::sim {

struct SensorOptics {
  std::string name;
  CameraModel colour;
  CameraModel ir;  // depth images share the IR camera's geometry
  Eigen::Isometry3d colour_from_ir = Eigen::Isometry3d::Identity();
  Eigen::Vector3d projector_in_ir{0.075, 0, 0};  // the speckle projector, ~7.5 cm away
  // Raw values at the periphery beyond this normalized radius read 2047
  // (the adapter's lost corners); infinite for stock optics.
  double usable_radius = 1e9;
};

SensorOptics StockOptics();
SensorOptics WideAngleOptics();
// "stock" or "wide_angle"; throws InputError otherwise.
SensorOptics OpticsByName(const std::string& name);

}  // namespace speckle::sim
