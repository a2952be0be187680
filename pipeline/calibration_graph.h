#pragma once
// run-pipeline's flow graph: the thesis's procedure, automatic.
#include <filesystem>

#include "pipeline/pipeline_result.h"
#include "stages/board_plane.h"
#include "stages/chessboard_detection.h"
#include "stages/depth_pose.h"
#include "stages/depthboard_quad.h"
#include "stages/pairing.h"
#include "stages/planar_cleanup.h"
#include "stages/raw_rate.h"
#include "stages/still_frame_average.h"
#include "stages/undistortion_grid.h"

namespace speckle {

struct PipelineOptions {
  ChessboardDetectionOptions detection;
  ChessboardTrackingOptions tracking;
  // Consecutive board frames handled as one task, so frames of a still pose
  // can track the board instead of searching for it; batches run in parallel.
  int batch_frames = 12;
  IntrinsicsOptions intrinsics;
  DepthboardQuadOptions quad;
  // How far (px) the nominal depth camera's outline prediction may be off,
  // for sessions whose depth camera comes from the outlines: a real Kinect's
  // IR camera sits up to about 15 px and 2 % from nominal, and the colour
  // camera a few millimetres and half a degree from its nominal place.
  double nominal_prediction_px = 60;
  // Depthboard quads from the median of up to this many consecutive frames of
  // a still pose (1 = each frame on its own). Pairing still reads each frame's
  // own raw values, so samples and the noise floor stay per frame.
  int still_frames_averaged = 1;
  StillFrameAverageOptions still_average;
  BoardRegionOptions board_region;  // boards larger than their chessboard
  JointPlaneOptions joint_plane;
  ExtrinsicsOptions extrinsics;
  DepthPoseOptions depth_pose;
  PairingOptions pairing;
  RawRateOptions raw_rate;
  PlanarCleanupOptions planar;
  UndistortionGridOptions grid;
  // Consecutive frames whose colour corners moved less than this are one still pose.
  double still_pose_motion_px = 2.0;
  // The board's image velocity is measured between consecutive frames at
  // most this far apart (a dropped frame or two, not a new pose much later).
  double max_velocity_gap_s = 0.1;
  int threads = 0;  // 0 = all cores
};

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
