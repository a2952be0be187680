#pragma once
// CPU time per stage of the calibration graph, summed over frames from any
// thread (report.json stage_seconds).
#include <array>
#include <atomic>
#include <chrono>
#include <vector>

#include "pipeline/pipeline_result.h"

namespace speckle {

// The graph's stages as report.json's stage_seconds names them: one entry
// in the enum and one in kStageNames each, in the same order.
enum StageId { kRead, kDetect, kTrack, kCalibrate, kQuad, kExtrinsics, kPosePair, kPlanarClean, kGrid, kStageCount };
inline constexpr std::array kStageNames = {
    "read",       "chessboard_detection",   "chessboard_tracking", "camera_calibration", "depthboard_quad",
    "extrinsics", "depth_pose_and_pairing", "planar_cleanup",      "undistortion_grid"};
static_assert(kStageNames.size() == kStageCount, "every StageId needs its name in kStageNames");

class StageClocks {
 public:
  template <typename F>
  auto Time(StageId stage, F&& body) {
    struct Stop {
      StageClocks* self;
      StageId stage;
      std::chrono::steady_clock::time_point start;
      ~Stop() {
        self->ns_[stage] +=
            std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start).count();
        ++self->calls_[stage];
      }
    } stop{this, stage, std::chrono::steady_clock::now()};
    return body();
  }
  std::vector<StageTiming> Timings() const {
    std::vector<StageTiming> out;
    for (int s = 0; s < kStageCount; ++s) out.push_back({kStageNames[s], ns_[s] * 1e-9, calls_[s].load()});
    return out;
  }

 private:
  std::array<std::atomic<std::int64_t>, kStageCount> ns_{};
  std::array<std::atomic<int>, kStageCount> calls_{};
};

}  // namespace speckle
