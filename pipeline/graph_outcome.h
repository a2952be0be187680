#pragma once
// What the calibration graph's collector keeps: every finished frame, with
// progress on a terminal, gathered in recording order into a PipelineResult
// once the graph is drained.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "pipeline/frame_work.h"
#include "pipeline/pipeline_result.h"
#include "recorder/progress.h"

namespace speckle {

// What became of the frames that were rejected, one line a reason with its
// count; when no chessboard was found in most of them, with the likelier
// cause than the poses: a board described by its inner corners.
std::string RejectionReasons(const std::map<std::string, int>& reasons);

class GraphOutcome {
 public:
  GraphOutcome(const std::string& tool, std::int64_t total_frames) : progress_(tool, total_frames) {}
  void Add(Frame frame);  // from one thread at a time

  // Frames, samples and snapshots, in recording order (IR, depthboard, planar).
  PipelineResult Gather();

  // Stops the run when the outlines could not give the depth camera, with
  // what became of the board frames and what to record.
  [[noreturn]] void ThrowDepthCameraFailure(const std::filesystem::path& session_dir, const std::string& why);

 private:
  Progress progress_;
  std::vector<Frame> finished_;
};

}  // namespace speckle
