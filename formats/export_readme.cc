#include "formats/export_readme.h"

#include <fmt/format.h>

#include "formats/tf_launch.h"
#include "model/depth_model.h"

namespace speckle::formats {
namespace {

std::string CameraLine(const char* name, const apply::PinholeCamera& c) {
  return fmt::format(
      "  {} camera: {}x{} px, fx {:.2f} fy {:.2f} cx {:.2f} cy {:.2f}, lens k1 k2 p1 p2 k3 = {:.5f} "
      "{:.5f} {:.6f} {:.6f} {:.5f}\n",
      name, c.width, c.height, c.fx, c.fy, c.cx, c.cy, c.distortion[0], c.distortion[1], c.distortion[2],
      c.distortion[3], c.distortion[4]);
}

// One line per frame file written, in the depth camera's grid unless registered.
std::string FrameFiles(const std::set<std::string>& formats) {
  const std::pair<const char*, const char*> kinds[] = {
      {"pcd",
       "RECORDING/NNNNNN.pcd         organized point cloud (binary PCD, PCL): x y z in metres in the depth "
       "camera's frame, one point per depth pixel, NaN where there is no reading; rgb from the colour "
       "frame where one was registered"},
      {"pcd-ascii", "RECORDING/NNNNNN.ascii.pcd   the same cloud as ASCII PCD"},
      {"ply", "RECORDING/NNNNNN.ply         the points that exist, x y z (metres, depth camera frame) and colour"},
      {"csv", "RECORDING/NNNNNN.csv         u,v,x_m,y_m,z_m,r,g,b: each point with the depth pixel it came from"},
      {"png",
       "RECORDING/NNNNNN.png         16-bit depth in millimetres (ROS 16UC1), 0 = no reading, in the depth "
       "camera's own pixel grid (not resampled: it pairs with depth_camera_info.yaml, lens included)"},
      {"registered-png",
       "RECORDING/NNNNNN.registered.png   depth registered to the colour camera (REP 118 "
       "16UC1): millimetres along the colour camera's axis, 0 = no reading, in "
       "rgb_camera_info.yaml's pixel grid"},
      {"registered-tiff",
       "RECORDING/NNNNNN.registered.tiff  the same in metres as a 32-bit float TIFF (REP 118 "
       "32FC1), NaN = no reading"}};
  std::string out;
  for (const auto& [format, text] : kinds)
    if (formats.count(format)) out += fmt::format("  {}\n", text);
  return out;
}

}  // namespace

std::string ExportReadme(const apply::DepthCalibration& c, const std::string& source,
                         const std::set<std::string>& formats, bool frames) {
  std::string out = fmt::format(
      "Speckle apply-calibration export\n\n"
      "Calibration: {}\n"
      "Depth model: {} (raw {} values to depth along the depth camera's optical axis)\n\n"
      "Frames and units\n"
      "  Every camera frame is an optical frame: x right, y down, z forward, in metres.\n"
      "  Depth is z (the distance along the optical axis), not the range along the ray.\n"
      "  The colour camera's frame is {}, the depth (IR) camera's {}.\n"
      "{}{}\n"
      "Files\n"
      "  depth_camera_info.yaml  ROS camera_info (plumb_bob) of the depth camera\n"
      "  rgb_camera_info.yaml    ROS camera_info of the colour camera\n"
      "  cameras_opencv.yml      both cameras and depth_from_colour (a colour-camera point to depth-camera "
      "coordinates), OpenCV FileStorage\n"
      "  depth_to_rgb_tf.launch  the same extrinsics for ROS: roslaunch starts tf2_ros's static_transform_publisher "
      "({} -> {})\n"
      "  applied.json            what was applied to which frames, and the frames skipped with why\n",
      source, c.model ? c.model->Definition().Describe() : std::string("(none)"),
      c.depth_units == DepthUnits::kMillimetre ? "millimetre" : "11-bit disparity", kColourOpticalFrame,
      kDepthOpticalFrame, CameraLine("colour", c.colour), CameraLine("depth", c.depth), kColourOpticalFrame,
      kDepthOpticalFrame);
  if (frames) out += FrameFiles(formats);
  out += "\nRECORDING is the session's recording (depthboard, planar, ...) and NNNNNN its frame index.\n";
  return out;
}

}  // namespace speckle::formats
