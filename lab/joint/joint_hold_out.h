#pragma once
// A depth model judged inside the joint calibration's problem: each still
// pose's depth samples predicted by a joint fit that never saw them, with
// the cameras, the extrinsics, every board pose and the model's parameters
// fitted again from the other poses' depths (and every pose's colour
// corners and outline, which place the held-out boards). So a candidate
// effect's held-out gain over the current model is the gain beyond what the
// cameras and poses can absorb (issue 46, point 2): the base form alone
// fitted jointly lets the cameras take up a hidden effect (bench/results/hunt.md).
#include <vector>

#include "lab/diagnosis/diagnosis.h"
#include "lab/fit/depth_fit.h"
#include "lab/joint/joint_calibration.h"

namespace speckle::joint {

// `in.cameras` is a joint calibration's (cameras.joint set): its cameras are
// the start and its terms' scatter the weights, the same for every model
// judged, so that one model's misfit does not lighten its own depth term.
// `in.form` and `in.effects` are the model judged; `folds` pose folds as the
// depth fit's (FoldsByPose). Residuals per input sample, measured minus
// predicted in the reading's units (NaN where no fold predicted it). Rejects
// without the joint calibration's weights or when no fold could be fitted.
// With `prediction_sigmas`, each held-out prediction's sigma from its fold's
// covariance as well (HeldOutFit::held_out_prediction_sigma_raw).
StageResult<HeldOutFit> HoldOutPosesJointly(const JointOptions& options, const JointInput& in, int folds,
                                            bool prediction_sigmas = true);

// The diagnosis's judge (lab/diagnosis/diagnosis.h) in this problem: each
// model it is given held out by HoldOutPosesJointly on the samples it is
// given. It keeps its own copies of what it is made from.
struct JointJudgeInput {
  JointOptions options;
  BoardGeometry board;
  CameraCalibration cameras;  // a joint calibration's
  DepthReading reading{};
  std::vector<BoardFrame> frames;
  int folds = 5;
};
HeldOutJudge MakeJointJudge(JointJudgeInput input);

}  // namespace speckle::joint
