#pragma once
// What a recording holds, fixed before its first frame: HDF5 in SWMR mode
// cannot add datasets or attributes once appending has started.
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "schemas/depth_reading.h"
#include "schemas/session_manifest.h"

namespace speckle {

// A float64 dataset with one entry of `shape` per frame, e.g. the simulator's
// true board pose at "truth/colour_from_board" with shape {4, 4}.
struct PerFrameSeries {
  std::string path;
  std::vector<int> shape;
  std::string description;
};

struct RecordingHeader {
  RecordingPurpose purpose = RecordingPurpose::kFree;
  std::string source;                   // "sim", "fakenect", "frames", "freenect"
  std::string source_path;              // where the frames came from, when a folder
  std::optional<cv::Size> colour_size;  // absent = the recording has no colour stream
  std::optional<cv::Size> depth_size;
  std::optional<cv::Size> ir_size;
  DepthUnits depth_units = DepthUnits::kRaw11Bit;
  bool has_accel = false;
  std::string device_registration_json;  // libfreenect device.json, empty = none
  std::string scenario_json;             // simulator scenario; non-empty adds /truth
  std::vector<PerFrameSeries> series;
};

// The value a depth pixel holds when the sensor has no reading.
inline int InvalidDepthValue(DepthUnits units) { return DepthReading(units).NoReadingValue(); }

}  // namespace speckle
