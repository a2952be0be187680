#include "pipeline/frame_feed.h"

#include "schemas/errors.h"

namespace speckle {
namespace {

// The images a recording's steps use: walls are cleaned from depth alone
// (their colour was half of a hunt session's decoding), IR chessboards are
// detected in IR alone.
unsigned StreamsUsed(RecordingPurpose recording) {
  switch (recording) {
    case RecordingPurpose::kPlanar:
      return kDepthStream;
    case RecordingPurpose::kIrChessboard:
      return kIrStream;
    default:
      return kColourStream | kDepthStream;
  }
}

}  // namespace

Frame FrameFeed::Next() {
  if (next_ >= reader_.frame_count()) return nullptr;
  auto f = std::make_shared<FrameWork>();
  f->recording = recording_;
  const std::int64_t in_file = next_++;
  f->index = static_cast<int>(first_index_ + in_file);
  FramePair pair;
  try {
    pair = reader_.ReadFrame(in_file, StreamsUsed(recording_));
  } catch (const InputError& e) {  // a damaged frame is skipped and reported, the rest calibrate
    f->rejection = Rejection{"read", e.what()};
    return f;
  }
  f->source_number = pair.source_number;
  f->colour_only = !pair.colour.image.empty() && pair.depth.image.empty();
  f->colour = pair.colour.image;
  f->raw = RawDepth(pair.depth.image, raw_source_, in_file);
  f->ir = pair.ir.image;
  f->time_s = clock_.Seconds(pair);
  return f;
}

}  // namespace speckle
