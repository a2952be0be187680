#pragma once
// PCL's point cloud format (PCD v0.7): organized (width x height, NaN where
// there is no point), fields x y z in metres and, with colour, rgb as PCL
// packs it (0x00RRGGBB, written as an unsigned integer so ASCII keeps it exact).
#include <string>

#include "apply/depth_corrector.h"

namespace speckle::formats {

enum class PcdEncoding { kBinary, kAscii };

std::string PcdFile(const apply::OrganizedCloud& cloud, PcdEncoding encoding);

}  // namespace speckle::formats
