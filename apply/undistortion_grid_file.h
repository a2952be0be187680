#pragma once
// undistortion_grid.h5 (schema "speckle.undistortion_grid", version 1; layout
// in schemas/calibration_format.md).
#include <filesystem>

#include "model/undistortion_grid.h"

namespace speckle {

void WriteGrid(const std::filesystem::path& path, const UndistortionGrid& grid);  // fails if the file exists
UndistortionGrid ReadGrid(const std::filesystem::path& path);  // throws InputError, SchemaVersionError

}  // namespace speckle
