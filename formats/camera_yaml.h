#pragma once
// A calibration's cameras in the YAML files other tools load:
//  - ROS camera_info (camera_calibration_parsers' format), one per camera,
//    distortion model plumb_bob. The depth camera's matches the unresampled
//    depth images and point clouds this tool writes.
//  - OpenCV FileStorage YAML with both cameras and the extrinsics, read with
//    cv::FileStorage (names in OpenCvCalibrationYaml below).
// Neither format can hold the depth model: that stays in calibration.json.
#include <string>

#include "apply/depth_calibration.h"

namespace speckle::formats {

inline constexpr int kOpenCvCalibrationSchemaVersion = 1;

std::string RosCameraInfoYaml(const apply::PinholeCamera& camera, const std::string& camera_name,
                              const std::string& source);
// Keys: schema ("speckle.cameras_opencv"), schema_version, source,
// {depth,colour}_image_size [w, h], {depth,colour}_camera_matrix 3x3,
// {depth,colour}_distortion_coefficients 1x5 (k1 k2 p1 p2 k3),
// depth_from_colour_rotation 3x3 and depth_from_colour_translation_m 3x1
// (a point in colour-camera coordinates to depth-camera coordinates).
std::string OpenCvCalibrationYaml(const apply::DepthCalibration& calibration, const std::string& source);

}  // namespace speckle::formats
