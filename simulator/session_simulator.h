#pragma once
// Turns a scenario into the frames of a simulated session: board poses over
// the usable range with realistic tilts and a time line (several frames per
// still pose, seconds between poses), and wall snapshots at many distances.
// Deterministic: every frame is rendered from the scenario seed and its index.
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <vector>

#include "simulator/scenario.h"
#include "simulator/scene_renderer.h"

namespace speckle::sim {

enum class SimRecording { kDepthboard, kPlanar };

struct SimFrameSpec {
  int index = 0;     // frame number within its recording
  int pose = 0;      // still pose (board) or snapshot (wall) it belongs to
  double time_s = 0; // since the session started
  TargetPose target;
};

struct SimFrame {
  cv::Mat colour_rgb;
  cv::Mat raw_depth;
};

class SessionSimulator {
 public:
  explicit SessionSimulator(const Scenario& scenario);

  const std::vector<SimFrameSpec>& Frames(SimRecording which) const {
    return which == SimRecording::kDepthboard ? depthboard_ : planar_;
  }
  // Thread-safe.
  SimFrame Render(SimRecording which, const SimFrameSpec& spec) const;

  const Scenario& scenario() const { return scenario_; }
  const SensorOptics& optics() const { return renderer_.optics(); }

 private:
  Scenario scenario_;
  SceneRenderer renderer_;
  std::vector<SimFrameSpec> depthboard_;
  std::vector<SimFrameSpec> planar_;
};

}  // namespace speckle::sim
