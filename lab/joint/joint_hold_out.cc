#include "lab/joint/joint_hold_out.h"

#include <tbb/parallel_for.h>

#include <Eigen/LU>
#include <algorithm>
#include <limits>
#include <map>
#include <memory>
#include <optional>

#include "lab/fit/fit_samples.h"
#include "lab/joint/joint_problem.h"
#include "lab/joint/joint_residuals.h"

namespace speckle::joint {
namespace {

// The held-out samples' residuals under the blocks a fold fitted.
void PredictHeldOut(const JointInput& in, const Sigmas& sigma, Blocks& b, const std::vector<std::size_t>& held_out,
                    std::vector<double>& residual) {
  for (std::size_t i : held_out) {
    const PairedSample& s = in.samples[i];
    if (!b.Pose(s.frame)) continue;
    const Term term = MakeDepthSampleTerm(in, sigma, b, s);
    const std::unique_ptr<ceres::CostFunction> cost(term.cost);
    double r = 0;
    if (cost->Evaluate(term.blocks.data(), &r, nullptr)) residual[i] = r * term.noise;
  }
}

// A held-out board's pose covariance from its colour corners and outline
// alone, the cameras held (6 x 6; empty when they do not pin it).
std::optional<Eigen::Matrix<double, 6, 6>> PoseCovariance(const JointInput& in, const BoardFrame& f,
                                                          const Sigmas& sigma, Blocks& b) {
  std::vector<Term> terms = ColourCornerTerms(in, f, sigma, b);
  std::vector<Term> outline = OutlineTerms(in, f, sigma, b);
  terms.insert(terms.end(), outline.begin(), outline.end());
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  for (const Term& t : terms) {
    const std::unique_ptr<ceres::CostFunction> cost(t.cost);
    double residual[2];
    Eigen::Matrix<double, 2, 6, Eigen::RowMajor> jacobian;
    std::vector<double*> jacobians(t.blocks.size(), nullptr);
    jacobians[0] = jacobian.data();  // the pose is every term's first block
    if (cost->Evaluate(t.blocks.data(), residual, jacobians.data())) information += jacobian.transpose() * jacobian;
  }
  const Eigen::FullPivLU<Eigen::Matrix<double, 6, 6>> lu(information);
  if (!lu.isInvertible()) return std::nullopt;
  return lu.inverse();
}

// Each held-out sample's depth sigma from its board's pose covariance.
void HeldOutTruthSigmas(const JointInput& in, const std::vector<const BoardFrame*>& frames, const Sigmas& sigma,
                        Blocks& b, const std::vector<std::size_t>& held_out, std::vector<double>& truth_sigma) {
  std::map<int, const BoardFrame*> frame_of;
  for (const BoardFrame* f : frames) frame_of[f->frame] = f;
  std::map<int, std::optional<Eigen::Matrix<double, 6, 6>>> covariance;
  for (std::size_t i : held_out) {
    const PairedSample& s = in.samples[i];
    const auto f = frame_of.find(s.frame);
    if (f == frame_of.end()) continue;
    auto at = covariance.find(s.frame);
    if (at == covariance.end()) at = covariance.emplace(s.frame, PoseCovariance(in, *f->second, sigma, b)).first;
    if (!at->second) continue;
    ceres::AutoDiffCostFunction<SampleDepth, 1, 6, 3, 3, 4, 5> depth(new SampleDepth(s.u, s.v));
    const double* blocks[5] = {b.Pose(s.frame), b.rotation, b.translation, b.depth_k, b.depth_lens};
    double z = 0;
    Eigen::Matrix<double, 1, 6> gradient;
    double* jacobians[5] = {gradient.data(), nullptr, nullptr, nullptr, nullptr};
    if (depth.Evaluate(blocks, &z, jacobians))
      truth_sigma[i] = std::sqrt(std::max(0.0, (gradient * *at->second * gradient.transpose())(0, 0)));
  }
}

}  // namespace

StageResult<HeldOutFit> HoldOutPosesJointly(const JointOptions& joint_options, const JointInput& in, int folds) {
  JointOptions options = joint_options;
  options.max_depth_samples = joint_options.hold_out_depth_samples;
  options.max_iterations = joint_options.hold_out_iterations;
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
  out.held_out_truth_sigma_m.assign(in.samples.size(), std::numeric_limits<double>::quiet_NaN());
  out.parameters = model::DepthModel(model::ModelDefinition{in.form, in.effects}).Flat().size();
  tbb::parallel_for(std::size_t{0}, tests.size(), [&](std::size_t f) {
    if (tests[f].empty()) return;
    Blocks b = start;
    std::vector<std::string> held;
    const Round round = FitRound(options, in, frames, sigma, b, &held, poses[f]);
    if (!round.summary.IsSolutionUsable() || round.kinds.depth.empty()) return;
    PredictHeldOut(in, sigma, b, tests[f], out.held_out_residual_raw);
    HeldOutTruthSigmas(in, frames, sigma, b, tests[f], out.held_out_truth_sigma_m);
  });
  out.held_out_raw = Summarize(out.held_out_residual_raw);
  if (out.held_out_raw.count == 0) return Rejection{"joint_hold_out", "no pose fold could be fitted jointly"};
  return out;
}

HeldOutJudge MakeJointJudge(JointJudgeInput input) {
  auto kept = std::make_shared<const JointJudgeInput>(std::move(input));
  return [kept](const model::ModelDefinition& definition, const std::vector<PairedSample>& samples) {
    const JointJudgeInput& k = *kept;
    return HoldOutPosesJointly(
        k.options, {k.board, k.cameras, definition.form, k.reading, k.frames, samples, definition.effects}, k.folds);
  };
}

}  // namespace speckle::joint
