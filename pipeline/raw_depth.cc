#include "pipeline/raw_depth.h"

#include "recorder/recording_reader.h"

namespace speckle {

RawSource::RawSource(std::filesystem::path path) : path_(std::move(path)) {}
RawSource::~RawSource() = default;

cv::Mat RawSource::Read(std::int64_t index) const {
  std::lock_guard lock(mutex_);
  if (!reader_) reader_ = std::make_unique<RecordingReader>(path_);
  return reader_->ReadFrame(index, kDepthStream).depth.image;
}

cv::Mat RawDepth::Image() const {
  if (!held_.empty() || !present_ || !source_) return held_;
  return source_->Read(index_);
}

}  // namespace speckle
