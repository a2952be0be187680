#pragma once
// The seam between a Kinect and the recorder: libfreenect's video and depth
// callbacks (raw buffers with the device's 60 MHz timestamps) go in, frame
// pairs come out as a FrameSource. The device code (freenect_source.cc) only
// forwards callbacks here, so a test can drive the real recorder, queue and
// writer with rendered frames instead of a Kinect.
//
// Callbacks arrive on libfreenect's event thread and never block: a pair that
// does not fit the bounded queue is counted as dropped.
#include <tbb/concurrent_queue.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>

#include "recorder/frame_source.h"

namespace speckle {

// libfreenect's video formats Speckle records.
enum class FreenectVideo {
  kColour,  // FREENECT_VIDEO_RGB: 640x480, 3 bytes a pixel, RGB order
  kIr,      // FREENECT_VIDEO_IR_8BIT: 640x488 on a Kinect v1, 1 byte a pixel
};

// The streams as the device was set up; sizes as freenect_get_current_video_mode reports them.
struct FreenectStreams {
  std::string device = "Kinect 0";  // names the device in messages
  FreenectVideo video = FreenectVideo::kColour;
  cv::Size video_size{640, 480};
  // 11-bit raw depth at 640x480. When off, each video frame is a pair by itself.
  bool depth = true;
};

struct FreenectFeedOptions {
  FreenectStreams streams;
  double duration_s = 0;  // 0 = until Ctrl-C or EndOfStream
  // Pairs buffered between the USB thread and the writer (about 4 s at 30 Hz).
  int queue_frames = 120;
};

// The image size a Kinect's depth and recorded IR frames have. The IR
// camera's 488-row frame is cropped to the depth image's 480 rows (its top
// rows kept, so pixel coordinates and the principal point do not move): the
// IR intrinsics the pipeline calibrates are then the depth camera's at the
// depth image's own size, as with the simulator's IR recordings.
inline const cv::Size kKinectDepthSize{640, 480};

class FreenectFrameFeed : public FrameSource {
 public:
  // Throws DeviceError, naming the device, when the streams are not ones a
  // Kinect v1 delivers (e.g. an IR mode narrower than 640 or under 480 rows).
  explicit FreenectFrameFeed(const FreenectFeedOptions& options);
  ~FreenectFrameFeed() override;

  // libfreenect's callbacks, forwarded: `data` holds one frame of the mode in
  // `streams`; `timestamp` is the device clock.
  void OnDepth(const void* data, std::uint32_t timestamp);
  void OnVideo(const void* data, std::uint32_t timestamp);
  // No more callbacks will come: Next() ends once the queue is drained.
  void EndOfStream() { ended_ = true; }

  std::optional<FramePair> Next() override;
  std::int64_t dropped() const { return dropped_; }

  // The header of a recording of these streams for `purpose`.
  RecordingHeader Header(RecordingPurpose purpose) const;

 private:
  StreamFrame VideoFrame(const void* data, std::uint32_t timestamp) const;
  void Push(FramePair pair);

  FreenectFeedOptions options_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  // Touched only on the callback thread.
  std::int64_t next_number_ = 0;
  StreamFrame latest_video_;
  tbb::concurrent_bounded_queue<FramePair> queue_;
  std::atomic<std::int64_t> dropped_{0};
  std::atomic<bool> ended_{false};
};

}  // namespace speckle
