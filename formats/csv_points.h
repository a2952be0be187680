#pragma once
// CSV of the points that exist: the pixel they came from, their position in
// metres (depth camera) and, with colour, their RGB; one header line.
#include <string>

#include "apply/depth_corrector.h"

namespace speckle::formats {

std::string CsvPoints(const apply::OrganizedCloud& cloud);

}  // namespace speckle::formats
