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

}  // namespace speckle
