#pragma once
// README.txt of an apply-calibration folder: what each file holds, in
// which units and which camera's frame, and the model that made it, so the
// folder can be used without this tool's documentation at hand.
#include <set>
#include <string>

#include "apply/depth_calibration.h"

namespace speckle::formats {

// `formats`: apply-calibration's --format values written; `frames`: whether frames were applied.
std::string ExportReadme(const apply::DepthCalibration& calibration, const std::string& source,
                         const std::set<std::string>& formats, bool frames);

}  // namespace speckle::formats
