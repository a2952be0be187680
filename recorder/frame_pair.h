#pragma once
// The records that flow from a frame source into a recording: one colour,
// depth and (optional) IR image taken together, with their clocks.
#include <array>
#include <cstdint>
#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace speckle {

struct StreamFrame {
  // colour: CV_8UC3 in RGB order; depth and IR: CV_16UC1. Empty = no frame
  // of this stream in this pair (stored with valid = 0).
  cv::Mat image;
  std::uint64_t device_timestamp = 0;  // the sensor's own clock (ticks)
  std::int64_t host_time_ns = 0;       // host wall clock, ns since the Unix epoch
  bool valid() const { return !image.empty(); }
};

// One libfreenect tilt-state sample (accelerometer counts: 819 per g).
struct AccelSample {
  std::int64_t host_time_ns = 0;
  std::uint64_t device_timestamp = 0;
  std::array<std::int16_t, 3> counts{};
  std::int8_t tilt_angle = 0;
  std::int8_t tilt_status = 0;
};

struct FramePair {
  StreamFrame colour;
  StreamFrame depth;
  StreamFrame ir;
  std::int64_t source_number = -1;  // the source's own frame number, -1 = none
  std::vector<AccelSample> accel;   // accelerometer samples since the previous pair
  // Values of the per-frame series the recording declared (e.g. ground-truth
  // poses), keyed by their path; each holds the declared shape's element count.
  std::map<std::string, std::vector<double>> series;
};

}  // namespace speckle
