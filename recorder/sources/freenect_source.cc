#include "recorder/sources/freenect_source.h"

#include <libfreenect.h>
#include <spdlog/spdlog.h>
#include <tbb/concurrent_queue.h>

#include <chrono>
#include <cstring>
#include <thread>

#include "schemas/errors.h"

namespace speckle {
namespace {

std::int64_t HostNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

class FreenectSource : public FrameSource {
 public:
  explicit FreenectSource(const FreenectCaptureOptions& options) : options_(options) {
    queue_.set_capacity(options.queue_frames);
    if (freenect_init(&context_, nullptr) < 0) throw DeviceError("libfreenect could not initialise USB");
    freenect_select_subdevices(context_, FREENECT_DEVICE_CAMERA);
    const int count = freenect_num_devices(context_);
    if (count <= options.device_index) {
      freenect_shutdown(context_);
      throw DeviceError("no Kinect found: libfreenect sees " + std::to_string(count) +
                        " device(s), wanted index " + std::to_string(options.device_index) +
                        " (check the USB cable, the power adapter and udev permissions)");
    }
    if (freenect_open_device(context_, &device_, options.device_index) < 0) {
      freenect_shutdown(context_);
      throw DeviceError("could not open Kinect " + std::to_string(options.device_index));
    }
    freenect_set_user(device_, this);
    freenect_set_depth_mode(device_, freenect_find_depth_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_DEPTH_11BIT));
    freenect_set_video_mode(device_, freenect_find_video_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_VIDEO_RGB));
    freenect_set_depth_callback(device_, &FreenectSource::OnDepth);
    freenect_set_video_callback(device_, &FreenectSource::OnVideo);
    freenect_start_depth(device_);
    freenect_start_video(device_);
    start_ = std::chrono::steady_clock::now();
    events_ = std::thread([this] {
      timeval timeout{0, 100000};
      while (!stop_) freenect_process_events_timeout(context_, &timeout);
    });
  }
  ~FreenectSource() override {
    stop_ = true;
    if (events_.joinable()) events_.join();
    freenect_stop_depth(device_);
    freenect_stop_video(device_);
    freenect_close_device(device_);
    freenect_shutdown(context_);
    if (dropped_ > 0) spdlog::warn("freenect: {} frame(s) dropped because the writer fell behind", dropped_.load());
  }

  std::optional<FramePair> Next() override {
    FramePair pair;
    while (true) {
      const bool out_of_time = options_.duration_s > 0 &&
                               std::chrono::steady_clock::now() - start_ > std::chrono::duration<double>(options_.duration_s);
      if (StopRequested() || out_of_time) return std::nullopt;
      if (queue_.try_pop(pair)) return pair;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }

 private:
  // Depth drives pairing: each depth frame takes the latest colour frame.
  static void OnDepth(freenect_device* device, void* data, std::uint32_t timestamp) {
    auto* self = static_cast<FreenectSource*>(freenect_get_user(device));
    FramePair pair;
    pair.source_number = self->next_number_++;
    pair.depth.image = cv::Mat(480, 640, CV_16UC1, data).clone();
    pair.depth.device_timestamp = timestamp;
    pair.depth.host_time_ns = HostNowNs();
    if (!self->latest_colour_.image.empty()) {
      pair.colour = self->latest_colour_;
      self->latest_colour_ = {};
    }
    if (!self->queue_.try_push(std::move(pair))) ++self->dropped_;
  }
  static void OnVideo(freenect_device* device, void* data, std::uint32_t timestamp) {
    auto* self = static_cast<FreenectSource*>(freenect_get_user(device));
    self->latest_colour_.image = cv::Mat(480, 640, CV_8UC3, data).clone();
    self->latest_colour_.device_timestamp = timestamp;
    self->latest_colour_.host_time_ns = HostNowNs();
  }

  FreenectCaptureOptions options_;
  freenect_context* context_ = nullptr;
  freenect_device* device_ = nullptr;
  std::thread events_;
  std::atomic<bool> stop_{false};
  std::atomic<std::int64_t> dropped_{0};
  std::int64_t next_number_ = 0;
  StreamFrame latest_colour_;
  tbb::concurrent_bounded_queue<FramePair> queue_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

PlannedRecording PlanFreenectCapture(const FreenectCaptureOptions& options, std::vector<std::string>* notes) {
  PlannedRecording planned;
  planned.file = ToString(options.purpose) + ".h5";
  planned.header.purpose = options.purpose;
  planned.header.source = "freenect";
  planned.header.colour_size = cv::Size(640, 480);
  planned.header.depth_size = cv::Size(640, 480);
  planned.header.depth_units = DepthUnits::kRaw11Bit;
  planned.source = std::make_unique<FreenectSource>(options);
  if (notes) notes->push_back("live capture from Kinect " + std::to_string(options.device_index));
  return planned;
}

}  // namespace speckle
