#pragma once
// The joint calibration's problem (joint_calibration.h): its parameter
// blocks, its three kinds of observation and one weighted solve. Shared by
// the calibration (which adds the covariance) and the pose hold-out that
// judges candidate effects in it (joint_hold_out.h).
#include <ceres/ceres.h>

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "lab/joint/joint_calibration.h"

namespace speckle::joint {

// Every parameter block of the joint problem.
struct Blocks {
  double colour_k[4], colour_lens[5], depth_k[4], depth_lens[5], rotation[3], translation[3];
  double edge_offset_px = 0;
  double billow[2] = {0, 0};
  // Depth exposed after colour (s): the outlines' lag behind a moving board.
  // With capture_time_offset in the model its parameter is this delay, so
  // the outlines and the raw values fit one (DelayBlock).
  double delay_s = 0;
  // The base form's parameters (the first base_size) and every frame's pose
  // (angle-axis, translation) in one array each: Ceres orders the Schur
  // elimination by the blocks' addresses, and poses scattered over a map's
  // nodes were eliminated in another order each run, moving the cameras in
  // the fifth digit.
  std::array<double, model::kMaxBaseParameters> base{};
  std::size_t base_size = 0;
  std::vector<std::array<double, 6>> pose_values;
  std::map<int, std::size_t> pose_of_frame;
  // The model's effects (JointInput::effects), their parameters its blocks.
  std::unique_ptr<model::DepthModel> model;

  Blocks() = default;
  Blocks(const Blocks& other);  // the model copied, so each copy is a problem of its own
  Blocks& operator=(Blocks&&) = default;
  std::vector<double*> EffectBlocks();
  double* DelayBlock();
  double* Pose(int frame);
};

// The start: the input's cameras and frame poses, the base form's and the
// effects' initial values.
Blocks StartBlocks(const JointInput& in);
void ToBlocks(const CameraIntrinsics& c, double* k, double* lens);  // k: fx, fy, cx, cy; lens: k1..k3
CameraIntrinsics FromBlocks(CameraIntrinsics c, const double* k, const double* lens);
Eigen::Isometry3d FromPose(const double* rotation, const double* translation);

// Each kind's noise (its unit), the weights of a solve.
struct Sigmas {
  double colour_px = 0.3, outline_px = 0.3, raw = 1.0;
};

// The residual blocks of one kind, to measure that kind's scatter.
struct Kinds {
  std::vector<ceres::ResidualBlockId> colour, outline, depth;
  std::vector<ceres::ResidualBlockId> prior;  // the session's cameras' priors (camera_priors.h), the effects'
  std::vector<ceres::ResidualBlockId> all;
  std::vector<int> pose;  // each of `all`'s still pose
  void Add(std::vector<ceres::ResidualBlockId>& kind, ceres::ResidualBlockId id, int still_pose) {
    kind.push_back(id), all.push_back(id), pose.push_back(still_pose);
  }
};

// Frames with a chessboard and samples (an outline too where it was found):
// the ones that tie the cameras together.
std::vector<const BoardFrame*> UsableFrames(const JointInput& in);

// A kind's RMS residual (per coordinate) in units of the sigma it was weighed with.
double RmsInSigmas(ceres::Problem& problem, const std::vector<ceres::ResidualBlockId>& ids);

// One observation's residual (in sigmas of `noise`, its unit) and the blocks
// it reads, for a problem or for evaluating it outside one.
struct Term {
  ceres::CostFunction* cost = nullptr;  // owned by whoever takes it
  std::vector<double*> blocks;
  double noise = 0;
};
Term MakeDepthSampleTerm(const JointInput& in, const Sigmas& sigma, Blocks& b, const PairedSample& s);
// A frame's colour corners (none unless it holds the whole board) and its outline's four corners.
std::vector<Term> ColourCornerTerms(const JointInput& in, const BoardFrame& f, const Sigmas& sigma, Blocks& b);
std::vector<Term> OutlineTerms(const JointInput& in, const BoardFrame& f, const Sigmas& sigma, Blocks& b);

// Where each block of a problem starts in a covariance's order.
struct Layout {
  std::vector<const double*> blocks;
  std::map<const double*, int> offset;
  int size = 0;
  void Add(ceres::Problem& problem, const double* block);
};
// Every block the problem holds, the poses first: so that each sigma counts
// what the others leave free (the base form trades against the extrinsics' depth).
Layout EveryBlock(ceres::Problem& problem, Blocks& b);

// A term's value (in its sigmas) and its gradient by a layout's order, the
// blocks outside the layout left out; nothing when it cannot be evaluated.
struct TermGradient {
  double value = 0;
  std::vector<std::pair<int, double>> gradient;  // (index, d value / d parameter)
};
std::optional<TermGradient> EvaluateTerm(const Term& term, const Layout& layout);

// One weighted fit from the blocks where they are; `problem` holds it after.
struct Round {
  std::unique_ptr<ceres::LossFunction> loss;  // outlives the problem that uses it
  std::unique_ptr<ceres::Problem> problem;
  Kinds kinds;
  ceres::Solver::Summary summary;
};
// `depth_held_out`: still poses whose depth samples the fit does not see
// (their colour corners and outlines it does, which place their boards).
Round FitRound(const JointOptions& options, const JointInput& in, const std::vector<const BoardFrame*>& frames,
               const Sigmas& sigma, Blocks& b, std::vector<std::string>* held,
               const std::set<int>& depth_held_out = {});

}  // namespace speckle::joint
