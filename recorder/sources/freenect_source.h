#pragma once
// Live capture from a Kinect v1 through libfreenect at 30 Hz: 11-bit raw
// depth and RGB, paired by the device's own timestamps.
#include "recorder/frame_source.h"

namespace speckle {

struct FreenectCaptureOptions {
  int device_index = 0;
  RecordingPurpose purpose = RecordingPurpose::kFree;
  double duration_s = 0;  // 0 = until Ctrl-C
  // Frames buffered between the USB thread and the writer (about 4 s at 30 Hz);
  // anything beyond is counted as dropped and reported.
  int queue_frames = 120;
};

// Throws DeviceError when no Kinect is attached.
PlannedRecording PlanFreenectCapture(const FreenectCaptureOptions& options, std::vector<std::string>* notes);

}  // namespace speckle
