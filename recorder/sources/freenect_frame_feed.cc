#include "recorder/sources/freenect_frame_feed.h"

#include <spdlog/spdlog.h>

#include <thread>

#include "schemas/errors.h"

namespace speckle {
namespace {

std::int64_t HostNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string SizeText(cv::Size size) { return std::to_string(size.width) + "x" + std::to_string(size.height); }

// The frame shapes this feed copies out of libfreenect's buffers; anything
// else would read past the buffer or misplace rows.
void CheckStreams(const FreenectStreams& s) {
  if (s.video == FreenectVideo::kColour && s.video_size != kKinectDepthSize) {
    throw DeviceError(s.device + ": colour video mode is " + SizeText(s.video_size) + ", expected 640x480 RGB");
  }
  if (s.video == FreenectVideo::kIr &&
      (s.video_size.width != kKinectDepthSize.width || s.video_size.height < kKinectDepthSize.height)) {
    throw DeviceError(s.device + ": IR video mode is " + SizeText(s.video_size) +
                      ", expected 640 wide and at least 480 rows (a Kinect v1 gives 640x488)");
  }
}

}  // namespace

FreenectFrameFeed::FreenectFrameFeed(const FreenectFeedOptions& options) : options_(options) {
  CheckStreams(options.streams);
  queue_.set_capacity(options.queue_frames);
}

FreenectFrameFeed::~FreenectFrameFeed() {
  if (dropped_ > 0) {
    spdlog::warn("{}: {} frame(s) dropped because the writer fell behind", options_.streams.device, dropped_.load());
  }
}

StreamFrame FreenectFrameFeed::VideoFrame(const void* data, std::uint32_t timestamp) const {
  StreamFrame frame;
  auto* bytes = const_cast<void*>(data);  // wrapped read-only, copied at once
  const cv::Size size = options_.streams.video_size;
  if (options_.streams.video == FreenectVideo::kColour) {
    frame.image = cv::Mat(size, CV_8UC3, bytes).clone();
  } else {
    // 8-bit IR widened to the format's 16-bit IR stream, values kept (0..255).
    cv::Mat(size, CV_8UC1, bytes)(cv::Rect({0, 0}, kKinectDepthSize)).convertTo(frame.image, CV_16U);
  }
  frame.device_timestamp = timestamp;
  frame.host_time_ns = HostNowNs();
  return frame;
}

// Depth drives pairing when it runs: each depth frame takes the latest video
// frame. Without depth (the IR step), every video frame is a pair.
void FreenectFrameFeed::OnDepth(const void* data, std::uint32_t timestamp) {
  if (!options_.streams.depth) return;
  FramePair pair;
  pair.depth.image = cv::Mat(kKinectDepthSize, CV_16UC1, const_cast<void*>(data)).clone();
  pair.depth.device_timestamp = timestamp;
  pair.depth.host_time_ns = HostNowNs();
  if (latest_video_.valid()) {
    (options_.streams.video == FreenectVideo::kIr ? pair.ir : pair.colour) = std::move(latest_video_);
    latest_video_ = {};
  }
  Push(std::move(pair));
}

void FreenectFrameFeed::OnVideo(const void* data, std::uint32_t timestamp) {
  StreamFrame frame = VideoFrame(data, timestamp);
  if (options_.streams.depth) {
    latest_video_ = std::move(frame);
    return;
  }
  FramePair pair;
  (options_.streams.video == FreenectVideo::kIr ? pair.ir : pair.colour) = std::move(frame);
  Push(std::move(pair));
}

void FreenectFrameFeed::Push(FramePair pair) {
  pair.source_number = next_number_++;
  if (!queue_.try_push(std::move(pair))) ++dropped_;
}

std::optional<FramePair> FreenectFrameFeed::Next() {
  FramePair pair;
  while (true) {
    const bool out_of_time = options_.duration_s > 0 && std::chrono::steady_clock::now() - start_ >
                                                            std::chrono::duration<double>(options_.duration_s);
    if (StopRequested() || out_of_time) return std::nullopt;
    if (queue_.try_pop(pair)) return pair;
    // Checked after an empty pop, then popped once more: a pair pushed just
    // before the end was marked is still delivered.
    if (ended_) return queue_.try_pop(pair) ? std::optional(std::move(pair)) : std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

RecordingHeader FreenectFrameFeed::Header(RecordingPurpose purpose) const {
  RecordingHeader header;
  header.purpose = purpose;
  header.source = "freenect";
  header.depth_units = DepthUnits::kRaw11Bit;
  if (options_.streams.depth) header.depth_size = kKinectDepthSize;
  if (options_.streams.video == FreenectVideo::kIr) {
    header.ir_size = kKinectDepthSize;
  } else {
    header.colour_size = kKinectDepthSize;
  }
  return header;
}

}  // namespace speckle
