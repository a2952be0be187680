#pragma once
// run-pipeline's flow graph: the thesis's procedure, automatic.
#include <filesystem>

#include "pipeline/pipeline_options.h"
#include "pipeline/pipeline_result.h"

namespace speckle {

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
