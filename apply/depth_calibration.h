#pragma once
// A calibration version as the apply library needs it: the cameras, the
// depth model with its fitted parameters, and the undistortion grid, read
// from calibrations/vNNNN/ (calibration.json, undistortion_grid.h5).
#include <Eigen/Geometry>
#include <filesystem>
#include <memory>
#include <optional>

#include "apply/pinhole_camera.h"
#include "schemas/depth_units.h"

// Internal to the library: users hold them, the corrector uses them.
namespace speckle {
struct UndistortionGrid;
namespace model {
class DepthModel;
}
}  // namespace speckle

namespace speckle::apply {

struct DepthCalibration {
  std::filesystem::path file;  // the calibration.json read
  PinholeCamera depth, colour;
  Eigen::Isometry3d depth_from_colour = Eigen::Isometry3d::Identity();
  std::shared_ptr<const model::DepthModel> model;
  std::shared_ptr<const UndistortionGrid> grid;  // when the fitted model applies one
  // The frames' units the model expects: millimetres for the linear_mm base
  // form (OpenNI drivers), 11-bit raw values otherwise.
  DepthUnits depth_units = DepthUnits::kRaw11Bit;
};

// `path`: a version directory or its calibration.json. Throws
// SchemaVersionError for a calibration (2 to 3) or grid (1) schema version it
// does not read, InputError naming the file and field for anything else.
DepthCalibration LoadDepthCalibration(const std::filesystem::path& path);

}  // namespace speckle::apply
