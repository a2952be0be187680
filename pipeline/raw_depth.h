#pragma once
// A frame's raw depth image, held in memory or read again from its recording.
//
// The graph's barriers hold every frame until all are in, and the steps after
// them still need each frame's raw image. Held throughout, 2000 frames take
// 1.2 GB; so past a budget of held frames (PipelineOptions::held_raw_frames)
// a frame's raw image is let go as soon as it is read and read again where a
// step needs it. Memory then grows with the budget and the frames in flight,
// not with the session; a short session reads each image once, as before.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>

#include <opencv2/core.hpp>

namespace speckle {

class RecordingReader;

// How many more frames may hold their raw image through the graph; shared
// by the graph's readers.
struct HeldRawBudget {
  explicit HeldRawBudget(int frames) : left(frames) {}
  bool Take() { return left.fetch_sub(1) > 0; }
  std::atomic<int> left;
};

// Reads raw depth images of one recording again; shared by its frames, and
// safe to call from several threads (HDF5 reads are serialized).
class RawSource {
 public:
  explicit RawSource(std::filesystem::path path);
  ~RawSource();
  cv::Mat Read(std::int64_t index) const;

 private:
  std::filesystem::path path_;
  mutable std::mutex mutex_;
  mutable std::unique_ptr<RecordingReader> reader_;  // opened on first use
};

class RawDepth {
 public:
  RawDepth() = default;
  // `image` as read; `source` and `index` read it again once it is let go.
  RawDepth(cv::Mat image, std::shared_ptr<const RawSource> source, std::int64_t index)
      : held_(std::move(image)), source_(std::move(source)), index_(index), present_(!held_.empty()) {}

  bool Present() const { return present_; }  // the frame has a depth image
  cv::Mat Image() const;                     // held, or read again; empty if not present
  void LetGo() { held_.release(); }          // read again when next needed
  void Release() { *this = RawDepth(); }     // no step needs it any more

 private:
  cv::Mat held_;
  std::shared_ptr<const RawSource> source_;
  std::int64_t index_ = -1;
  bool present_ = false;
};

}  // namespace speckle
