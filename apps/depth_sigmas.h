#pragma once
// The depth sigma a calibration version states (its report.json's
// depth_uncertainty rows), for the tools that put a ± on what they read
// from a calibration: measure, compare and check.
#include <filesystem>
#include <string>

#include "apply/point_measure.h"

namespace speckle {

// The calibration.json a tool is given: a session (its newest version), a
// version folder or the file itself. Throws InputError naming `given`.
std::filesystem::path CalibrationFile(const std::string& given);

// Empty when the version has no report.json or it states no rows. Throws
// InputError / SchemaVersionError for a report it cannot read.
apply::DepthSigmaTable DepthSigmasOf(const std::filesystem::path& calibration_file);

}  // namespace speckle
