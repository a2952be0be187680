#include "recorder/sources/freenect_source.h"

#include <libfreenect.h>
#include <spdlog/spdlog.h>

#include <thread>

#include "recorder/sources/freenect_frame_feed.h"
#include "schemas/errors.h"

namespace speckle {
namespace {

// Opens the device, sets its modes and forwards libfreenect's callbacks to a
// FreenectFrameFeed, which does everything else (and is what tests drive).
class FreenectDevice {
 public:
  FreenectDevice(const FreenectCaptureOptions& options, FreenectStreams* streams) {
    const std::string name = streams->device;
    if (freenect_init(&context_, nullptr) < 0) throw DeviceError(name + ": libfreenect could not initialise USB");
    freenect_select_subdevices(context_, FREENECT_DEVICE_CAMERA);
    const int count = freenect_num_devices(context_);
    if (count <= options.device_index) {
      freenect_shutdown(context_);
      throw DeviceError("no Kinect found: libfreenect sees " + std::to_string(count) + " device(s), wanted index " +
                        std::to_string(options.device_index) +
                        " (check the USB cable, the power adapter and udev permissions)");
    }
    if (freenect_open_device(context_, &device_, options.device_index) < 0) {
      freenect_shutdown(context_);
      throw DeviceError("could not open " + name);
    }
    const freenect_video_format format =
        streams->video == FreenectVideo::kIr ? FREENECT_VIDEO_IR_8BIT : FREENECT_VIDEO_RGB;
    if (freenect_set_video_mode(device_, freenect_find_video_mode(FREENECT_RESOLUTION_MEDIUM, format)) < 0) {
      Close();
      throw DeviceError(name + ": the device refused video mode " +
                        (format == FREENECT_VIDEO_IR_8BIT ? "IR 8-bit" : "RGB") + " at medium resolution");
    }
    // The frame size the device delivers, not the one we assume.
    const freenect_frame_mode mode = freenect_get_current_video_mode(device_);
    streams->video_size = cv::Size(mode.width, mode.height);
    if (streams->depth) {
      freenect_set_depth_mode(device_, freenect_find_depth_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_DEPTH_11BIT));
    }
  }
  ~FreenectDevice() {
    stop_ = true;
    if (events_.joinable()) events_.join();
    if (depth_started_) freenect_stop_depth(device_);
    if (video_started_) freenect_stop_video(device_);
    Close();
  }

  // Callbacks start now and go to `feed` until this object is destroyed.
  void Start(FreenectFrameFeed* feed, bool depth) {
    freenect_set_user(device_, feed);
    freenect_set_video_callback(device_, [](freenect_device* d, void* data, std::uint32_t timestamp) {
      static_cast<FreenectFrameFeed*>(freenect_get_user(d))->OnVideo(data, timestamp);
    });
    freenect_set_depth_callback(device_, [](freenect_device* d, void* data, std::uint32_t timestamp) {
      static_cast<FreenectFrameFeed*>(freenect_get_user(d))->OnDepth(data, timestamp);
    });
    if (depth) depth_started_ = freenect_start_depth(device_) >= 0;
    video_started_ = freenect_start_video(device_) >= 0;
    events_ = std::thread([this] {
      timeval timeout{0, 100000};
      while (!stop_) freenect_process_events_timeout(context_, &timeout);
    });
  }

 private:
  void Close() {
    freenect_close_device(device_);
    freenect_shutdown(context_);
  }

  freenect_context* context_ = nullptr;
  freenect_device* device_ = nullptr;
  std::thread events_;
  std::atomic<bool> stop_{false};
  bool depth_started_ = false, video_started_ = false;
};

// The feed and the device that drives it, as one FrameSource. The device is
// opened first (it reports the frame sizes the feed checks) and stopped first
// (no callback may reach a destroyed feed).
class FreenectSource : public FrameSource {
 public:
  FreenectSource(const FreenectCaptureOptions& options, FreenectStreams streams)
      : device_(std::make_unique<FreenectDevice>(options, &streams)),
        feed_(std::make_unique<FreenectFrameFeed>(
            FreenectFeedOptions{streams, options.duration_s, options.queue_frames})) {
    device_->Start(feed_.get(), streams.depth);
  }
  ~FreenectSource() override { device_.reset(); }
  std::optional<FramePair> Next() override { return feed_->Next(); }
  const FreenectFrameFeed& feed() const { return *feed_; }

 private:
  std::unique_ptr<FreenectDevice> device_;
  std::unique_ptr<FreenectFrameFeed> feed_;
};

}  // namespace

PlannedRecording PlanFreenectCapture(const FreenectCaptureOptions& options, std::vector<std::string>* notes) {
  FreenectStreams streams;
  streams.device = "Kinect " + std::to_string(options.device_index);
  const bool ir = options.purpose == RecordingPurpose::kIrChessboard;
  if (ir) {
    streams.video = FreenectVideo::kIr;
    // With the projector covered depth has nothing to read, and the IR camera is the depth camera.
    streams.depth = false;
    spdlog::warn("{}", kCoverProjectorInstruction);
  }
  auto source = std::make_unique<FreenectSource>(options, streams);
  PlannedRecording planned;
  planned.file = ToString(options.purpose) + ".h5";
  planned.header = source->feed().Header(options.purpose);
  planned.source = std::move(source);
  if (notes) {
    notes->push_back("live capture from " + streams.device +
                     (ir ? ": IR camera only (640x488 cropped to 640x480)" : ""));
  }
  return planned;
}

}  // namespace speckle
