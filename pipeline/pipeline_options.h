#pragma once
// Every option of a run-pipeline run, stage by stage.
#include <optional>
#include <string>

#include "lab/diagnosis/diagnosis.h"
#include "lab/joint/joint_calibration.h"
#include "schemas/depth_reading.h"
#include "stages/board_plane.h"
#include "stages/camera_calibration.h"
#include "stages/chessboard_detection.h"
#include "stages/depth_pose.h"
#include "stages/depthboard_quad.h"
#include "stages/outline_calibration.h"
#include "stages/pairing.h"
#include "stages/planar_cleanup.h"
#include "stages/raw_rate.h"
#include "stages/still_frame_average.h"
#include "stages/undistortion_grid.h"

namespace speckle {

struct PipelineOptions {
  // Which depth values are readings: the session's depth units, set once by
  // ForDepthUnits (pipeline/calibration_graph.h) and handed to every stage
  // that reads a raw image.
  DepthReading reading;
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
  // Frames that keep their raw image (600 KB at VGA) from reading until
  // pairing; the rest read it again where a step needs it (pipeline/raw_depth.h).
  // 250 covers a user's session (25 poses x 3 frames + walls) several times
  // over, so only sessions far longer pay for reading twice.
  int held_raw_frames = 250;
  std::string refit_tool = "refit";  // how the user calls refit, for the verdict's commands
  DiagnosisOptions diagnosis;
  // The cameras, extrinsics and base form refined together from every board
  // frame's observations, after the separate steps (lab/joint/joint_calibration.h).
  joint::JointOptions joint;
  // check (apps/check_main.cc): a calibration's cameras and extrinsics, held.
  // Nothing is calibrated; every board frame is outlined and paired with
  // them, so the samples test that calibration on this session's frames.
  std::optional<CameraCalibration> held_cameras;

  // False, with the first rule broken in *why (naming its field, as
  // "planar.segmentation.stride"), for options no run can use: these and
  // every stage's own.
  bool IsValid(std::string* why) const;
};

}  // namespace speckle
