#pragma once
// Live capture from a Kinect v1 through libfreenect at 30 Hz: 11-bit raw
// depth and RGB, paired by the device's own timestamps; or, for an
// `ir_chessboard` recording, the IR camera alone (the thesis's IR step: IR
// images of the chessboard with the projector covered, for the depth
// camera's intrinsics).
#include "recorder/frame_source.h"

namespace speckle {

struct FreenectCaptureOptions {
  int device_index = 0;
  // kIrChessboard records libfreenect's IR video (FREENECT_VIDEO_IR_8BIT)
  // without depth; every other purpose records depth + RGB.
  RecordingPurpose purpose = RecordingPurpose::kFree;
  double duration_s = 0;  // 0 = until Ctrl-C
  // Frames buffered between the USB thread and the writer (about 4 s at 30 Hz);
  // anything beyond is counted as dropped and reported.
  int queue_frames = 120;
};

// What the user must do before an IR chessboard recording, printed on the terminal.
inline constexpr const char* kCoverProjectorInstruction =
    "IR chessboard recording: cover the IR projector (the outer window farthest from the two "
    "cameras, on the left as you face the Kinect) - its speckle pattern hides the chessboard. "
    "Light the board with an IR source such as an incandescent lamp or sunlight, and hold it still "
    "at each pose, as for the depthboard.";

// Throws DeviceError when no Kinect is attached or it offers no usable mode.
PlannedRecording PlanFreenectCapture(const FreenectCaptureOptions& options, std::vector<std::string>* notes);

}  // namespace speckle
