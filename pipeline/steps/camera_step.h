#pragma once
// A named step of the calibration graph, its first barrier: once every
// detection is in, the colour and depth cameras are calibrated and every
// board frame gets its still pose, its colour pose and its motion.
//
// The depth camera comes, in order, from the session's own intrinsics, an
// IR chessboard recording, or (neither given) the depthboard outlines, which
// the extrinsics step fits (pipeline/steps/extrinsics_step.h); until then it
// is the Kinect's nominal camera.
#include <vector>

#include "pipeline/frame_work.h"
#include "pipeline/pipeline_options.h"
#include "schemas/session_manifest.h"

namespace speckle {

struct CameraStepInput {
  const PipelineOptions& options;
  const BoardGeometry& board;
  const SessionManifest& manifest;
  cv::Size depth_size;
  bool plane_mode = false;  // boards larger than their chessboard: the board planes give the depth camera
};

struct CameraStepResult {
  CameraCalibration cameras;
  bool depth_camera_from_outlines = false;  // the extrinsics step fits the depth camera
};

// `frames`: every frame of the session (any recording), in any order. Board
// frames are rejected when the colour camera cannot be calibrated.
CameraStepResult CalibrateCameras(const CameraStepInput& in, std::vector<Frame>& frames);

// The cameras session.json gives with standard deviations, as the joint
// calibration's priors (CameraCalibration::colour_prior, depth_prior). A
// refit attaches them again: calibration.json does not hold them.
void AttachSessionPriors(const SessionManifest& manifest, CameraCalibration& cameras);

// The Kinect's nominal depth camera (ROS defaults): where the outlines are
// first looked for when nothing gives the depth camera.
CameraIntrinsics NominalDepthCamera(cv::Size size);

}  // namespace speckle
