#include "formats/camera_yaml.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <opencv2/core.hpp>

namespace speckle::formats {
namespace {

cv::Matx33d CameraMatrix(const apply::PinholeCamera& c) { return {c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1}; }

}  // namespace

std::string RosCameraInfoYaml(const apply::PinholeCamera& c, const std::string& camera_name,
                              const std::string& source) {
  // {} prints each double as the shortest text that reads back to it.
  return fmt::format(
      "# ROS camera_info (camera_calibration_parsers) written by Speckle from {}\n"
      "image_width: {}\nimage_height: {}\ncamera_name: {}\n"
      "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [{}, 0, {}, 0, {}, {}, 0, 0, 1]\n"
      "distortion_model: plumb_bob\n"
      "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [{}]\n"
      "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
      "projection_matrix:\n  rows: 3\n  cols: 4\n  data: [{}, 0, {}, 0, 0, {}, {}, 0, 0, 0, 1, 0]\n",
      source, c.width, c.height, camera_name, c.fx, c.cx, c.fy, c.cy, fmt::join(c.distortion, ", "), c.fx, c.cx, c.fy,
      c.cy);
}

std::string OpenCvCalibrationYaml(const apply::DepthCalibration& calibration, const std::string& source) {
  cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  fs << "schema"
     << "speckle.cameras_opencv";
  fs << "schema_version" << kOpenCvCalibrationSchemaVersion;
  fs << "source" << source;
  for (const auto& [name, camera] :
       {std::pair{"depth", &calibration.depth}, std::pair{"colour", &calibration.colour}}) {
    const std::string prefix = name;
    fs << prefix + "_image_size" << cv::Size(camera->width, camera->height);
    fs << prefix + "_camera_matrix" << cv::Mat(CameraMatrix(*camera));
    fs << prefix + "_distortion_coefficients" << cv::Mat(cv::Matx<double, 1, 5>(camera->distortion.data()));
  }
  cv::Matx33d rotation;
  cv::Vec3d translation;
  for (int r = 0; r < 3; ++r) {
    translation[r] = calibration.depth_from_colour.translation()[r];
    for (int c = 0; c < 3; ++c) rotation(r, c) = calibration.depth_from_colour.linear()(r, c);
  }
  fs << "depth_from_colour_rotation" << cv::Mat(rotation);
  fs << "depth_from_colour_translation_m" << cv::Mat(translation);
  return fs.releaseAndGetString();
}

}  // namespace speckle::formats
