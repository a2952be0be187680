#pragma once
// What a depth frame's values are: the sensor's 11-bit raw values, or
// millimetres (OpenNI drivers, ROS and TUM recordings). Public: the apply
// library's calibrations say which their model expects.
#include <string>

namespace speckle {

enum class DepthUnits { kRaw11Bit, kMillimetre };
std::string ToString(DepthUnits units);
DepthUnits DepthUnitsFromString(const std::string& text);  // throws InputError

}  // namespace speckle
