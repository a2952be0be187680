#pragma once
// Corrected depth registered to the colour camera, as ROS's depth_registered
// images are (REP 118: 32FC1 metres, NaN for no reading): every point of a
// corrected cloud moved into the colour camera by the calibration's
// extrinsics and projected through its lens onto the colour pixel it falls
// in. Where several fall in one pixel the nearest is kept (the others are
// hidden behind it from the colour camera); a colour pixel no point falls in
// holds no reading. Nothing is interpolated, so no depth is made up at an
// edge. The values are depths along the colour camera's optical axis.
#include <vector>

#include "apply/depth_calibration.h"
#include "apply/depth_corrector.h"

namespace speckle::apply {

// The colour camera's width x height depths (metres), row-major, NaN where none.
std::vector<float> RegisteredDepth(const OrganizedCloud& cloud, const DepthCalibration& calibration);

}  // namespace speckle::apply
