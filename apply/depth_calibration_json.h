#pragma once
// Inside the tree only (not installed: the public headers need Eigen alone):
// a calibration from its calibration.json as read, for a writer that checks
// a version before it is written (refit's unseen regions).
#include <filesystem>
#include <nlohmann/json.hpp>

#include "apply/depth_calibration.h"

namespace speckle::apply {

// `file`: where the document is (or will be); its grid is read beside it.
// Throws as LoadDepthCalibration does.
DepthCalibration DepthCalibrationFromJson(const nlohmann::json& calibration, const std::filesystem::path& file);

}  // namespace speckle::apply
