#pragma once
// The built-in simulator as a frame source: one depthboard and one planar
// recording per scenario, with ground truth under /truth.
#include <nlohmann/json.hpp>

#include "recorder/frame_source.h"
#include "simulator/scenario.h"

namespace speckle {

struct SimCaptureOptions {
  // Emit frames at the scenario's frame rate, like a live sensor (for demos
  // and for testing what a killed recorder leaves behind).
  bool realtime = false;
};

SessionPlan PlanSimulatedSession(const sim::Scenario& scenario, const SimCaptureOptions& options);

}  // namespace speckle
