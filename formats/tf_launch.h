#pragma once
// The depth (IR) camera's place relative to the colour camera as ROS loads
// it: a roslaunch file starting tf2_ros's static_transform_publisher, whose
// arguments are x y z qx qy qz qw frame_id child_frame_id, the child's pose
// in the parent frame (here the depth optical frame in the colour optical
// frame: a point's depth-camera coordinates to its colour-camera ones).
// Frame names are the openni / freenect launch files' defaults.
#include <string>

#include "apply/depth_calibration.h"

namespace speckle::formats {

inline constexpr const char* kColourOpticalFrame = "camera_rgb_optical_frame";
inline constexpr const char* kDepthOpticalFrame = "camera_depth_optical_frame";

std::string StaticTransformLaunch(const apply::DepthCalibration& calibration, const std::string& source);

}  // namespace speckle::formats
