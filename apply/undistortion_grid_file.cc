#include "apply/undistortion_grid_file.h"

#include "schemas/artifact_schema.h"
#include "schemas/h5_access.h"

namespace speckle {

namespace fs = std::filesystem;

void WriteGrid(const fs::path& path, const UndistortionGrid& g) {
  H5::H5File file(path.string(), H5F_ACC_EXCL);
  h5::WriteStringAttribute(file, "schema", "speckle.undistortion_grid");
  h5::WriteIntAttribute(file, "schema_version", kGridSchemaVersion);
  h5::WriteStringAttribute(file, "true_raw_method", ToString(g.method));
  h5::WriteStringAttribute(
      file, "meaning",
      "r' = raw + correction(raw, y, x), trilinear; x, y normalized undistorted depth coordinates, "
      "cells evenly spaced over [x_min, x_max] x [y_min, y_max]");
  H5::Group root = file.openGroup("/");
  h5::WriteVector(root, "raw_nodes", g.raw_nodes, H5::PredType::NATIVE_DOUBLE, {g.raw_nodes.size()});
  h5::WriteVector(root, "extent_x_min_x_max_y_min_y_max", std::vector<double>{g.x_min, g.x_max, g.y_min, g.y_max},
                  H5::PredType::NATIVE_DOUBLE, {4});
  const std::vector<hsize_t> dims{g.raw_nodes.size(), hsize_t(g.ny), hsize_t(g.nx)};
  h5::WriteVector(root, "correction", g.correction, H5::PredType::NATIVE_FLOAT, dims);
  h5::WriteVector(root, "std_error", g.std_error, H5::PredType::NATIVE_FLOAT, dims);
  h5::WriteVector(root, "supported", g.supported, H5::PredType::NATIVE_UINT8, dims);
}

UndistortionGrid ReadGrid(const fs::path& path) {
  const std::string where = path.string();
  return ReadArtifactH5(
      path, "speckle.undistortion_grid", kGridSchemaVersion, kGridSchemaVersion, "no undistortion grid", "grid",
      [&](const H5::H5File& file, int) {
        UndistortionGrid g;
        g.raw_nodes = h5::ReadVector<double>(file, "raw_nodes", H5::PredType::NATIVE_DOUBLE, where);
        const auto extent =
            h5::ReadVector<double>(file, "extent_x_min_x_max_y_min_y_max", H5::PredType::NATIVE_DOUBLE, where);
        if (extent.size() != 4) throw InputError(where + ": extent must hold 4 numbers");
        g.x_min = extent[0], g.x_max = extent[1], g.y_min = extent[2], g.y_max = extent[3];
        const auto dims = h5::Dimensions(file.openDataSet("correction"));
        if (dims.size() != 3 || dims[0] != g.raw_nodes.size() || dims[1] > kMaxGridCells || dims[2] > kMaxGridCells)
          throw InputError(where + ": /correction has the wrong shape (expected [raw nodes, ny, nx])");
        g.ny = static_cast<int>(dims[1]);
        g.nx = static_cast<int>(dims[2]);
        g.correction = h5::ReadVector<float>(file, "correction", H5::PredType::NATIVE_FLOAT, where);
        g.std_error = h5::ReadVector<float>(file, "std_error", H5::PredType::NATIVE_FLOAT, where);
        g.supported = h5::ReadVector<std::uint8_t>(file, "supported", H5::PredType::NATIVE_UINT8, where);
        if (const std::string problem = g.Problem(); !problem.empty()) throw InputError(where + ": " + problem);
        return g;
      });
}

}  // namespace speckle
