#include "formats/tf_launch.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <regex>

namespace speckle::formats {

std::string StaticTransformLaunch(const apply::DepthCalibration& calibration, const std::string& source) {
  const Eigen::Isometry3d colour_from_depth = calibration.depth_from_colour.inverse();
  const Eigen::Quaterniond q(colour_from_depth.linear());
  const Eigen::Vector3d t = colour_from_depth.translation();
  // An XML comment may not hold "--", which a path may.
  return fmt::format(
      "<launch>\n"
      "  <!-- Speckle: the depth camera's optical frame in the colour camera's, from {} -->\n"
      "  <node pkg=\"tf2_ros\" type=\"static_transform_publisher\" name=\"speckle_rgb_to_depth\"\n"
      "        args=\"{:.9f} {:.9f} {:.9f} {:.12f} {:.12f} {:.12f} {:.12f} {} {}\" />\n"
      "</launch>\n",
      std::regex_replace(source, std::regex("--"), "- -"), t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w(),
      kColourOpticalFrame, kDepthOpticalFrame);
}

}  // namespace speckle::formats
