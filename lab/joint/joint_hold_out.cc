#include "lab/joint/joint_hold_out.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <memory>

#include "lab/fit/fit_samples.h"
#include "lab/joint/cluster_covariance.h"
#include "lab/joint/joint_problem.h"
#include "lab/joint/joint_residuals.h"

namespace speckle::joint {
namespace {

// The held-out samples' residuals under the blocks a fold fitted, and each
// prediction's sigma from the fold's covariance: the held-out board placed
// by its colour corners and outline, the cameras, extrinsics and base form
// fitted to the other poses. Through the residual's gradient, so that what
// the base form takes up of the cameras' error is not counted as error (the
// true depth's gradient alone stated a floor four times the held-out error
// of clean sessions).
// The fold's covariance for the predictions' sigmas: the corners' and
// outlines' errors clustered by pose, the depth samples' counted at their
// weight, since a model judged that lacks an effect leaves residuals shared
// within each pose, which must not widen the floor it is compared with.
std::optional<Eigen::MatrixXd> FoldCovariance(const Round& round, const Layout& layout) {
  std::vector<int> cluster = round.kinds.pose;
  const std::set<ceres::ResidualBlockId> depth(round.kinds.depth.begin(), round.kinds.depth.end());
  for (std::size_t r = 0; r < cluster.size(); ++r)
    if (depth.count(round.kinds.all[r])) cluster[r] = -1;
  return ClusterRobustCovariance(*round.problem, round.kinds.all, cluster, layout.blocks);
}

void PredictHeldOut(const JointInput& in, const Sigmas& sigma, Blocks& b, const Round& round,
                    const std::vector<std::size_t>& held_out, bool prediction_sigmas, HeldOutFit& out) {
  const Layout layout = EveryBlock(*round.problem, b);
  const auto covariance = prediction_sigmas ? FoldCovariance(round, layout) : std::nullopt;
  for (std::size_t i : held_out) {
    const PairedSample& s = in.samples[i];
    if (!b.Pose(s.frame)) continue;
    const Term term = MakeDepthSampleTerm(in, sigma, b, s);
    const std::unique_ptr<ceres::CostFunction> cost(term.cost);
    const auto evaluated = EvaluateTerm(term, layout);
    if (!evaluated) continue;
    out.held_out_residual_raw[i] = evaluated->value * term.noise;
    if (!covariance) continue;
    double variance = 0;
    for (const auto& [a, da] : evaluated->gradient)
      for (const auto& [c, dc] : evaluated->gradient) variance += da * (*covariance)(a, c) * dc;
    out.held_out_prediction_sigma_raw[i] = std::sqrt(std::max(0.0, variance)) * term.noise;
  }
}

}  // namespace

StageResult<HeldOutFit> HoldOutPosesJointly(const JointOptions& joint_options, const JointInput& in, int folds,
                                            bool prediction_sigmas) {
  JointOptions options = joint_options;
  options.max_depth_samples = joint_options.hold_out_depth_samples;
  options.max_iterations = joint_options.hold_out_iterations;
  options.function_tolerance = joint_options.hold_out_function_tolerance;
  options.billow_nuisance = false;
  if (!in.cameras.joint || in.cameras.joint->terms.size() < 3)
    return Rejection{"joint_hold_out", "the cameras are not a joint calibration's, so there are no weights"};
  const auto frames = UsableFrames(in);
  if (frames.size() < 3) return Rejection{"joint_hold_out", "fewer than 3 board frames tie the cameras together"};
  const auto& terms = in.cameras.joint->terms;
  const Sigmas sigma{terms[0].rms, terms[1].rms, terms[2].rms};
  const Blocks start = StartBlocks(in);
  const std::vector<int> fold = FoldsByPose(in.samples, folds);
  std::vector<std::vector<std::size_t>> tests(static_cast<std::size_t>(std::max(folds, 0)));
  std::vector<std::set<int>> poses(tests.size());
  for (std::size_t i = 0; i < in.samples.size(); ++i) {
    if (fold[i] < 0 || fold[i] >= folds) continue;
    tests[static_cast<std::size_t>(fold[i])].push_back(i);
    poses[static_cast<std::size_t>(fold[i])].insert(in.samples[i].pose);
  }
  HeldOutFit out;
  out.held_out_residual_raw.assign(in.samples.size(), std::numeric_limits<double>::quiet_NaN());
  out.held_out_prediction_sigma_raw.assign(in.samples.size(), std::numeric_limits<double>::quiet_NaN());
  out.parameters = model::DepthModel(model::ModelDefinition{in.form, in.effects}).Flat().size();
  const auto& depth = in.cameras.depth;
  out.principal_point_from_depth_image = (in.cameras.depth_intrinsics_source == "depth_outlines" ||
                                          in.cameras.depth_intrinsics_source == "joint_board_planes") &&
                                         depth.stddev[2] > 0 && depth.stddev[3] > 0;
  tbb::parallel_for(std::size_t{0}, tests.size(), [&](std::size_t f) {
    if (tests[f].empty()) return;
    Blocks b = start;
    std::vector<std::string> held;
    const Round round = FitRound(options, in, frames, sigma, b, &held, poses[f]);
    if (!round.summary.IsSolutionUsable() || round.kinds.depth.empty()) return;
    PredictHeldOut(in, sigma, b, round, tests[f], prediction_sigmas, out);
  });
  out.held_out_raw = Summarize(out.held_out_residual_raw);
  if (out.held_out_raw.count == 0) return Rejection{"joint_hold_out", "no pose fold could be fitted jointly"};
  return out;
}

HeldOutJudge MakeJointJudge(JointJudgeInput input) {
  auto kept = std::make_shared<const JointJudgeInput>(std::move(input));
  return [kept](const model::ModelDefinition& definition, const std::vector<PairedSample>& samples,
                bool prediction_sigmas) {
    const JointJudgeInput& k = *kept;
    return HoldOutPosesJointly(k.options,
                               {k.board, k.cameras, definition.form, k.reading, k.frames, samples, definition.effects},
                               k.folds, prediction_sigmas);
  };
}

}  // namespace speckle::joint
