#pragma once
// Everything one run of the calibration graph produced, before it is written
// as artifacts.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "lab/fit/depth_fit.h"
#include "lab/joint/joint_calibration.h"
#include "pipeline/pipeline_options.h"
#include "schemas/session_manifest.h"
#include "stages/board_size_in_depth.h"
#include "stages/camera_calibration.h"
#include "stages/planar_cleanup.h"
#include "stages/records.h"
#include "stages/undistortion_grid.h"

namespace speckle {

// What became of one frame.
struct FrameOutcome {
  std::string recording;  // purpose
  int index = 0;
  std::int64_t source_number = -1;
  int pose = -1;
  int samples = 0;
  std::optional<Rejection> rejection;
  std::optional<double> quad_edge_rms_px;  // depthboard frames whose outline was found
  std::optional<WallMask> rejected_wall;   // a rejected planar frame's segmented wall, if it got that far
  // A board frame with colour alone whose chessboard was found: it
  // calibrates the colour camera and is not rejected (the depth steps'
  // kNoDepthImage is dropped).
  bool colour_view = false;
};

struct StageTiming {
  std::string stage;
  double seconds = 0;  // summed over frames (CPU time in the stage)
  int calls = 0;
};

struct PipelineResult {
  // The options the graph ran with: the caller's, for the session's depth
  // units (ForDepthUnits), which every step after the graph uses too.
  PipelineOptions options;
  CameraCalibration cameras;
  BoardGeometry board;
  DepthUnits depth_units = DepthUnits::kRaw11Bit;
  std::vector<ExtrinsicsView> extrinsics_views;  // what the extrinsics were fitted to
  // The board's size by the depth's own triangulation, when its outline is
  // the chessboard's edge and the depth is the 11-bit disparity.
  std::optional<BoardSizeInDepth> board_size_in_depth;
  // Every paired board frame's colour corners and outline, for the joint
  // calibration (RunCalibration).
  std::vector<joint::BoardFrame> board_observations;
  // Every paired sample; RunCalibration moves them into its model lab
  // (CalibrationRun::lab.samples), so they are held once.
  std::vector<PairedSample> samples;
  // With board-plane pairing: every sample's depth under each direction of
  // the joint fit's uncertainty ([direction][sample]; else empty).
  std::vector<std::vector<double>> plane_perturbations;
  std::vector<PlanarSnapshot> snapshots;
  bool planar_recording = false;  // the session has one: the grid is built from its snapshots
  std::optional<UndistortionGrid> grid;
  std::optional<Rejection> grid_rejection;
  std::vector<FrameOutcome> frames;
  std::vector<StageTiming> timings;
  double wall_seconds = 0;
  int board_frames = 0;
  int colour_view_frames = 0;  // board frames with no depth image: views for the colour camera alone
  int paired_frames = 0;
  int still_frames_averaged = 1;  // quads found in the median of this many frames of a pose
};

}  // namespace speckle
