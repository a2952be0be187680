#pragma once
// One frame on its way through the calibration graph (pipeline/calibration_graph.cc),
// and the two ways a step records what became of it.
#include <memory>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/raw_depth.h"
#include "schemas/session_manifest.h"
#include "stages/board_plane.h"
#include "stages/camera_calibration.h"
#include "stages/depthboard_quad.h"
#include "stages/planar_cleanup.h"
#include "stages/records.h"

namespace speckle {

struct FrameWork {
  RecordingPurpose recording = RecordingPurpose::kDepthboard;
  int index = 0;
  std::int64_t source_number = -1;
  bool colour_only = false;  // a colour image and no depth (see kNoDepthImage)
  double time_s = 0;
  cv::Mat colour, ir;
  RawDepth raw;
  std::optional<ChessboardDetection> detection;
  Eigen::Isometry3d colour_from_board = Eigen::Isometry3d::Identity();
  PoseCovariance colour_pose_covariance = PoseCovariance::Zero();
  std::vector<RawDepth> still_neighbours;  // raw frames of the same still pose, for quad averaging
  std::optional<DepthboardQuad> quad;
  std::optional<BoardRegion> region;
  std::vector<PairedSample> samples;
  // The joint board-plane fit's uncertainty: [direction][sample], each
  // sample's depth moved one sigma along each (JointPlanePerturbations).
  std::vector<std::vector<double>> plane_perturbations;
  std::optional<PlanarSnapshot> snapshot;
  std::optional<WallMask> rejected_wall;  // a planar frame rejected after its wall was segmented
  std::optional<Rejection> rejection;
  int pose = -1;
  double motion_px = 0;
  Eigen::Vector2d velocity_px_s = Eigen::Vector2d::Zero();
  // The board centre's velocity in the colour camera (m/s). Only the centre:
  // a pose's rotation about its centre is its least certain part, and the
  // difference of two poses 33 ms apart would turn its scatter into motion
  // (1 degree between a detected and a tracked frame reads as 0.1 m/s at the
  // board's edge).
  Eigen::Vector3d board_velocity = Eigen::Vector3d::Zero();

  bool IsBoard() const { return recording == RecordingPurpose::kDepthboard; }
};
using Frame = std::shared_ptr<FrameWork>;
using Batch = std::vector<Frame>;

// Runs a step's body; an escaping exception becomes the frame's rejection.
template <typename F>
void Guarded(FrameWork& f, const char* stage, F&& body) {
  if (f.rejection) return;
  try {
    body();
  } catch (const std::exception& e) {
    f.rejection = Rejection{stage, std::string("failed: ") + e.what()};
  }
}

// A stage's result into the frame: its value, or its rejection.
template <typename T>
void Take(FrameWork& f, StageResult<T> result, std::optional<T>* into) {
  if (Accepted(result)) {
    *into = std::move(std::get<T>(result));
  } else {
    f.rejection = std::get<Rejection>(result);
  }
}

}  // namespace speckle
