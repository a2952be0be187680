#pragma once

#include <optional>
#include <string>
#include <vector>

#include "lab/diagnosis/diagnosis.h"
#include "lab/joint/joint_calibration.h"
#include "lab/model_spec.h"
#include "stages/outline_calibration.h"
#include "stages/raw_rate.h"

namespace speckle {

// What run-pipeline and refit need to fit the cameras jointly with a model
// (lab/joint/joint_calibration.h): the start cameras and every board frame.
struct JointCamerasInput {
  const joint::JointOptions& options;
  const ExtrinsicsOptions& extrinsics;  // the limits LooselyPinned judges the joint depth camera by
  const BoardGeometry& board;
  const CameraCalibration& start;
  const ModelSpec& spec;
  DepthReading reading;
  const std::vector<joint::BoardFrame>& frames;
  const std::vector<PairedSample>& samples;
  int folds = 5;      // the diagnosis's, for its joint judge
  std::string kept;   // whose cameras stay when the fit fails: "the separate steps'"
  std::string again;  // said after the model's name in the log: "" or " again"
  // The samples' rates are taken again at a fixed pixel (RawRateOptions::at_fixed_pixel):
  // the joint calibration puts each sample's depth on its pixel's ray.
  RawRateOptions raw_rate = {};
};

// The joint fit's outcome: the cameras (the depth camera's loose-intrinsics
// warning judged anew), the samples moved to where they put them, the joint
// uncertainty's directions as perturbations (fitted with the model, so not
// in the floor), and the diagnosis's judge in the same problem.
struct JointCameras {
  CameraCalibration cameras;
  std::vector<PairedSample> samples;
  DepthPerturbations perturbations;
  HeldOutJudge judge;
};

// Nothing when the fit is refused: said, with whose cameras are kept.
std::optional<JointCameras> FitCamerasJointly(const JointCamerasInput& input);

}  // namespace speckle
