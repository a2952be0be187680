#pragma once
// run-pipeline's flow graph: the thesis's procedure, automatic.
#include <filesystem>
#include <functional>
#include <optional>

#include "pipeline/frame_work.h"
#include "pipeline/pipeline_options.h"
#include "pipeline/pipeline_result.h"
#include "schemas/session_manifest.h"

namespace speckle {

// One recording as the graph reads it: `next` gives its frames in recording
// order, then null. Called from one thread at a time.
struct RecordingStream {
  std::int64_t frames = 0;
  std::function<Frame()> next;
};

// What one run of the graph reads: the session's description and its
// recordings (the depthboard's required, planar and IR when present).
struct GraphInput {
  std::filesystem::path session_dir;  // named in errors
  SessionManifest manifest;
  cv::Size depth_size;  // of the depthboard recording
  RecordingStream boards;
  std::optional<RecordingStream> planar, ir;
};

// Runs every stage on `input`'s frames. Throws InputError when the session
// cannot be calibrated at all (no board described); frame-level problems
// are FrameOutcome rejections. The session-directory form below opens the
// recordings and calls this; tests call it on frames made in memory.
PipelineResult RunCalibrationGraph(const GraphInput& input, const PipelineOptions& options);

// Reads the session's recordings (depthboard required; planar and
// ir_chessboard used when present) and runs every stage. Throws InputError
// when the session cannot be calibrated at all (no board description, no
// depthboard recording); frame-level problems are FrameOutcome rejections.
PipelineResult RunCalibrationGraph(const std::filesystem::path& session_dir, const PipelineOptions& options);

// The stages' options for a session's depth units: one no-reading rule
// (schemas/depth_reading.h) for every stage, and the board-plane fits in the
// units' base form (linear_mm for millimetres). RunCalibrationGraph applies
// it to the options it is given.
PipelineOptions ForDepthUnits(PipelineOptions options, DepthUnits units);

}  // namespace speckle
