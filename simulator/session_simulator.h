#pragma once
// Turns a scenario into the frames of a simulated session: board poses over
// the usable range with realistic tilts and a time line (several frames per
// still pose, tens of seconds between poses), wall snapshots at many
// distances, and IR images of the board. Deterministic: every frame is
// rendered from the scenario seed and its index, in any order.
#include <Eigen/Geometry>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <vector>

#include "simulator/scenario.h"
#include "simulator/scene_renderer.h"
#include "simulator/sim_effect.h"

namespace speckle::sim {

struct SimFrameSpec {
  int index = 0;  // frame number within its recording
  FrameContext context;
  TargetPose colour_target;      // where the target is when colour (and IR) is exposed
  TargetPose depth_target;       // ... and when depth is exposed
  std::vector<Clutter> clutter;  // the nearest object covering a pixel hides the others
};

struct SimFrame {
  cv::Mat colour_rgb;  // empty for IR chessboard frames
  cv::Mat raw_depth;   // empty for IR chessboard frames
  cv::Mat ir;          // IR chessboard frames only
};

// The preset optics with the scenario's camera overrides applied.
SensorOptics OpticsFor(const Scenario& scenario);

class SessionSimulator {
 public:
  explicit SessionSimulator(const Scenario& scenario);

  const std::vector<SimFrameSpec>& Frames(SimRecording which) const { return frames_[static_cast<int>(which)]; }
  // Thread-safe.
  SimFrame Render(SimRecording which, const SimFrameSpec& spec) const;
  // What each depth pixel's ray hits, without noise or effects (for tests and evaluation).
  DepthTruth TrueDepth(const SimFrameSpec& spec) const { return renderer_->TrueDepth(spec.depth_target, spec.clutter); }

  const Scenario& scenario() const { return scenario_; }
  const SensorOptics& optics() const { return renderer_->optics(); }
  const SceneRenderer& renderer() const { return *renderer_; }

 private:
  // What every frame of one still pose shares: its true depth and its clean
  // picture. Rendering them once per pose instead of once per frame halves
  // a session's rendering; each frame still draws its own noise.
  struct StillScene {
    SimFrameSpec spec;
    DepthTruth truth;  // empty for IR chessboard frames
    cv::Mat clean_grey;
  };
  std::shared_ptr<const StillScene> StillSceneOf(SimRecording which, const SimFrameSpec& spec) const;

  Scenario scenario_;
  std::vector<std::unique_ptr<SimEffect>> effects_;
  std::unique_ptr<SceneRenderer> renderer_;
  std::array<std::vector<SimFrameSpec>, 3> frames_;
  mutable std::mutex still_mutex_;
  mutable std::array<std::shared_ptr<const StillScene>, 3> last_still_;  // per recording
};

}  // namespace speckle::sim
