#pragma once
// One bundle adjustment over every observation a session's board frames
// hold: the colour chessboard corners, the depth outline corners and the
// depth samples' raw values on the board planes. Its parameters are both
// cameras with their lenses, the extrinsics, the outline's edge offset, every
// board frame's pose, and the depth model's base form (Herrera et al.'s joint
// formulation).
//
// The separate steps (the colour camera from its chessboards, then the depth
// camera from the outlines given the colour poses) are its start. Fitted
// apart, the colour camera's uncertainty moves every pose and the depth
// camera's moves the extrinsics along the axis, and no data pins either
// against the other: measured on held-out recordings, depth was then known to
// about 1 % and the cameras became the floor. Jointly, a tilted board's
// samples tie its poses' depths to the depth camera and the base form, and
// each camera's uncertainty is what all the data leave.
//
// Each kind of observation is weighed by its own scatter, estimated from the
// fit (two rounds), so that no kind outweighs the others by its count.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "model/base_form.h"
#include "model/depth_model.h"
#include "schemas/depth_reading.h"
#include "stages/records.h"

namespace speckle::joint {

// One board frame as the joint fit sees it: its colour corners and, when
// found, its depth outline.
struct BoardFrame {
  int frame = 0;
  int pose = 0;  // still pose: its frames share their errors (see cluster_covariance.h)
  Eigen::Isometry3d colour_from_board = Eigen::Isometry3d::Identity();  // the start
  std::vector<cv::Point2f> colour_corners;                              // interior corners, row-major
  std::optional<DepthboardQuad> quad;
  Eigen::Vector3d board_velocity = Eigen::Vector3d::Zero();  // colour-camera m/s (with a fitted delay)
};

struct JointOptions {
  // The default (run-pipeline --separate-cameras turns it off): it cuts a
  // clean session's depth error threefold, and the diagnosis judges every
  // candidate inside this problem, so the cameras cannot hide an effect.
  bool enabled = true;
  // The depth term's samples, evenly thinned to at most this many: more
  // pin nothing more (a pose's samples share its pose's error) and cost time.
  int max_depth_samples = 6000;
  int max_iterations = 60;
  double function_tolerance = 1e-6;  // Ceres' default: the calibration's cost to six digits
  double huber_sigmas = 3.0;         // every term's robust loss, in its own sigmas
  int weighting_rounds = 1;          // fits before the last, each weighing the kinds by the one before's scatter
  // The cameras' joint uncertainty reaches the depth model as this many
  // directions at most (the largest of every sample depth's covariance).
  int max_directions = 8;
  // Each model the diagnosis holds out in this problem (joint_hold_out.h) is
  // fitted on at most this many depth samples and iterations per fold: it
  // ranks models by their held-out error, which needs neither the last digit
  // nor every sample of a pose that shares its pose's error.
  int hold_out_depth_samples = 2000;
  int hold_out_iterations = 30;
  // Each fold starts at the joint calibration's minimum: its held-out error
  // settles long before the cost's sixth digit does (thermal drift seed 1:
  // 362 iterations instead of 606 over the diagnosis's folds, every
  // candidate's held-out error within 4 %; bench/results/hunt.md).
  double hold_out_function_tolerance = 1e-4;
  // The calibration fits a radial billow of the raw values beside the model
  // so that the depth lens does not take it up. A model held out is judged
  // as it is delivered, without it (unless radial_billow is one of its
  // effects): with it, a hidden billow's sessions stood at the floor and
  // the radial_billow candidate gained nothing (bench/results/hunt.md).
  bool billow_nuisance = true;
  // A model whose effects carry more parameters is not fitted jointly (the
  // cameras given are kept): every fold of its diagnosis would refit them
  // all with the cameras. With disparity_pattern's 768, a 160-pose
  // session's record, run and refit went past its test's 15 minutes once the
  // effects' priors entered the joint covariance (350 s before, in CI);
  // spatial_field's 44 fit jointly in 3.4 s on Herrera's set.
  int max_effect_parameters = 100;
  // False, naming the first broken rule's field in *why (schemas/option_check.h).
  bool IsValid(std::string* why) const;
};

struct JointInput {
  const BoardGeometry& board;
  const CameraCalibration& cameras;  // the separate steps' cameras: the start
  model::BaseForm form = model::BaseForm::kReciprocal;
  DepthReading reading{};
  const std::vector<BoardFrame>& frames;
  const std::vector<PairedSample>& samples;
  // The model's effects, fitted with the base form, the cameras and the
  // poses (their covariates the samples' as the separate steps gave them).
  std::vector<model::EffectSpec> effects = {};
};

struct JointCalibration {
  // With standard deviations from the joint covariance, and its account
  // (terms: colour corners and outline corners in px, depth samples in raw).
  CameraCalibration cameras;
  // Each sample's depth on its board plane, then moved by one sigma along
  // each of the largest directions of the joint uncertainty ([direction][sample]).
  std::vector<double> depths;
  std::vector<std::vector<double>> perturbations;
  std::vector<std::vector<double>> effect_parameters;  // per JointInput::effects
  // Each sample's depth sigma left beyond those directions (its own pose's).
  std::vector<double> residual_sigma_m;
};

// Rejects when too few frames hold both a chessboard and an outline, or the fit fails.
StageResult<JointCalibration> RunJointCalibration(const JointOptions& options, const JointInput& input);

// The samples where the joint cameras put them: depth, normalized
// coordinates, board point in the colour camera and depth sigma.
void MoveSamples(const JointCalibration& joint, std::vector<PairedSample>& samples);

}  // namespace speckle::joint
