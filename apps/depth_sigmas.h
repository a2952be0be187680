#pragma once
// The depth sigma a calibration version states (its report.json's
// depth_uncertainty rows), for the tools that put a ± on what they read
// from a calibration: measure and compare.
#include <filesystem>

#include "apply/point_measure.h"

namespace speckle {

// Empty when the version has no report.json or it states no rows. Throws
// InputError / SchemaVersionError for a report it cannot read.
apply::DepthSigmaTable DepthSigmasOf(const std::filesystem::path& calibration_file);

}  // namespace speckle
