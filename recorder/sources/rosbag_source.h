#pragma once
// Imports a ROS 1 bag (freenect_launch / openni_launch recordings) through
// Debian's rosbag_storage library: sensor_msgs/Image on a depth and a colour
// topic, paired by header stamp with the fakenect import's rule (nearest
// within --max-pair-gap-ms, 20 ms by default; frames left alone stop the
// import unless --allow-unpaired keeps them).
//
// Encodings: depth 16UC1 (raw 11-bit values, or millimetres as REP 118 and
// both drivers publish them: given by --depth-units or detected, see
// DetectDepthUnits) and 32FC1 (metres, stored as millimetres); colour rgb8,
// bgr8 and bayer_grbg8; IR (--purpose ir_chessboard, the IR topic) mono16.
// Anything else, a missing topic, or frames whose size changes stop the
// import with a message naming the topic. Every message is read and checked
// before any frame is written. A frame's number is its depth (IR) message's
// index on its topic, from 0; a colour frame kept alone has its colour
// message's.
#include <filesystem>
#include <optional>

#include "recorder/frame_source.h"

namespace speckle {

struct RosbagImportOptions {
  RecordingPurpose purpose = RecordingPurpose::kDepthboard;
  std::string depth_topic = "/camera/depth/image_raw";
  std::string colour_topic = "/camera/rgb/image_color";
  std::string ir_topic = "/camera/ir/image_raw";  // read instead of the others for ir_chessboard
  std::optional<DepthUnits> depth_units;          // of 16UC1 depth; nullopt: detect
  double max_pair_gap_s = 0.020;
  bool allow_unpaired = false;
  // Keep the first camera_info beside each image topic (same namespace) as
  // the session's known intrinsics (plumb_bob only).
  bool use_camera_info = false;
};

struct RosbagImport {
  PlannedRecording recording;
  DepthUnits depth_units = DepthUnits::kMillimetre;
  std::optional<KnownIntrinsics> colour_intrinsics, depth_intrinsics;
};

// Throws InputError naming the bag and the topic.
RosbagImport PlanRosbagImport(const std::filesystem::path& bag, const RosbagImportOptions& options,
                              std::vector<std::string>* notes);

// 16UC1 depth without a stated unit: values above 2047 are millimetres; 2047
// (libfreenect's no reading) with no 0 anywhere is raw 11-bit; 0 (REP 118's
// no reading) is millimetres. With neither mark and no value beyond 11 bits
// the values fit both, and nothing is returned: a fully lit raw scene is not
// millimetres. `why` says which rule held, or why none did.
std::optional<DepthUnits> DetectDepthUnits(std::uint16_t max_value, std::int64_t zeros, std::int64_t at_2047,
                                           std::string* why);

}  // namespace speckle
