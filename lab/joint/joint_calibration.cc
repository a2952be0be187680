#include "lab/joint/joint_calibration.h"

#include <fmt/format.h>

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "lab/joint/cluster_covariance.h"
#include "lab/joint/joint_problem.h"
#include "lab/joint/joint_residuals.h"
#include "schemas/option_check.h"
#include "stages/scaled_covariance.h"

namespace speckle::joint {
namespace {

// Every sample's depth on its board plane and its gradient by the covariance's order.
struct SampleGradients {
  std::vector<double> depth;
  std::vector<std::vector<std::pair<int, double>>> gradient;  // (index, d depth / d parameter)
};

SampleGradients DepthGradients(const JointInput& in, Blocks& b, const Layout& layout) {
  SampleGradients out;
  out.depth.resize(in.samples.size());
  out.gradient.resize(in.samples.size());
  for (std::size_t i = 0; i < in.samples.size(); ++i) {
    const PairedSample& s = in.samples[i];
    double* pose = b.Pose(s.frame);
    if (!pose) {
      out.depth[i] = s.depth_m;
      continue;
    }
    ceres::AutoDiffCostFunction<SampleDepth, 1, 6, 3, 3, 4, 5> cost(new SampleDepth(s.u, s.v));
    const double* params[5] = {pose, b.rotation, b.translation, b.depth_k, b.depth_lens};
    constexpr int kSizes[5] = {6, 3, 3, 4, 5};
    std::array<double, 21> jacobian{};
    double* jacobians[5];
    for (int k = 0, at = 0; k < 5; at += kSizes[k], ++k) jacobians[k] = jacobian.data() + at;
    cost.Evaluate(params, &out.depth[i], jacobians);
    for (int k = 0; k < 5; ++k) {
      auto where = layout.offset.find(params[k]);
      if (where == layout.offset.end()) continue;
      for (int j = 0; j < kSizes[k]; ++j) out.gradient[i].push_back({where->second + j, jacobians[k][j]});
    }
  }
  return out;
}

// The largest directions of every sample depth's covariance G S G^T (G the
// gradients, S the parameters' covariance): S = L L^T, the eigenvectors w of
// L^T G^T G L give directions L w, each sample moved by its gradient along
// them; what they leave of each sample's variance is its residual sigma.
void DepthDirections(const JointOptions& options, const SampleGradients& g, const Eigen::MatrixXd& covariance,
                     JointCalibration& out) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> s(covariance);
  const Eigen::MatrixXd root = s.eigenvectors() * s.eigenvalues().cwiseMax(0).cwiseSqrt().asDiagonal();
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(covariance.rows(), covariance.cols());
  for (const auto& row : g.gradient)
    for (const auto& [a, da] : row)
      for (const auto& [c, dc] : row) gram(a, c) += da * dc;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> directions(root.transpose() * gram * root);
  const int n = static_cast<int>(directions.eigenvalues().size());
  const int keep = std::min(options.max_directions, n);
  std::vector<double> explained(g.depth.size(), 0);
  for (int d = 0; d < keep; ++d) {
    const Eigen::VectorXd along = root * directions.eigenvectors().col(n - 1 - d);
    std::vector<double>& moved = out.perturbations.emplace_back(g.depth);
    for (std::size_t i = 0; i < g.depth.size(); ++i) {
      double shift = 0;
      for (const auto& [a, da] : g.gradient[i]) shift += da * along(a);
      moved[i] += shift;
      explained[i] += shift * shift;
    }
  }
  out.residual_sigma_m.resize(g.depth.size());
  for (std::size_t i = 0; i < g.depth.size(); ++i) {
    double variance = 0;
    for (const auto& [a, da] : g.gradient[i])
      for (const auto& [c, dc] : g.gradient[i]) variance += da * covariance(a, c) * dc;
    out.residual_sigma_m[i] = std::sqrt(std::max(0.0, variance - explained[i]));
  }
}

// A camera's standard deviations and its terms' covariance from the
// problem's (zero for terms held).
void CameraSigmas(const Eigen::MatrixXd& covariance, const Layout& layout, const double* k, const double* lens,
                  CameraIntrinsics& camera) {
  camera.covariance = CameraCovariance(covariance, layout.offset, k, lens);
  for (std::size_t i = 0; i < 9; ++i) camera.stddev[i] = std::sqrt(std::max(0.0, camera.covariance[10 * i]));
}

// The depth camera's terms whose sigma an effect more than doubles: with
// the effect's parameters known, the term's variance is what the covariance
// leaves of it (the Schur complement). Without outlines a spatial field's
// planes and the principal point are one signature (Herrera's set: cx +- 6.0
// px with spatial_field, 1.7 without), and the user is told which.
std::vector<std::string> EffectTrades(const Eigen::MatrixXd& covariance, const Layout& layout, Blocks& b) {
  static const char* kNames[4] = {"fx", "fy", "cx", "cy"};
  std::vector<std::string> out;
  const auto k_at = layout.offset.find(b.depth_k);
  if (k_at == layout.offset.end()) return out;
  for (std::size_t e = 0; e < b.model->Effects().size(); ++e) {
    const auto at = layout.offset.find(b.model->EffectParameters(e).data());
    if (at == layout.offset.end()) continue;
    std::vector<int> free;  // a held parameter's rows are zero
    for (int p = 0; p < static_cast<int>(b.model->EffectParameters(e).size()); ++p)
      if (covariance(at->second + p, at->second + p) > 0) free.push_back(at->second + p);
    if (free.empty()) continue;
    const Eigen::MatrixXd effect = covariance(free, free);
    const Eigen::LDLT<Eigen::MatrixXd> solve(effect);
    for (int i = 0; i < 4; ++i) {
      const int t = k_at->second + i;
      const double variance = covariance(t, t);
      if (!(variance > 0)) continue;
      const Eigen::VectorXd shared = covariance(free, t);
      const double known = std::max(0.0, variance - shared.dot(solve.solve(shared)));
      if (std::sqrt(variance) <= 2 * std::sqrt(known)) continue;
      out.push_back(fmt::format("depth {} ± {:.2f} px is ± {:.2f} px with {}'s parameters known", kNames[i],
                                std::sqrt(variance), std::sqrt(known), b.model->Effects()[e]->Name()));
    }
  }
  return out;
}

}  // namespace

StageResult<JointCalibration> RunJointCalibration(const JointOptions& options, const JointInput& in) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("joint calibration's options: " + why);
  const auto frames = UsableFrames(in);
  if (frames.size() < 3)
    return Rejection{"joint_calibration",
                     std::to_string(frames.size()) + " board frames hold a chessboard and depth samples; it needs 3"};
  Blocks b = StartBlocks(in);
  if (const int n = static_cast<int>(b.model->Flat().size() - b.model->Base().size());
      n > options.max_effect_parameters)
    return Rejection{"joint_calibration",
                     fmt::format("the model's effects carry {} parameters, over the {} a joint fit "
                                 "takes (max_effect_parameters)",
                                 n, options.max_effect_parameters)};
  const auto start = std::chrono::steady_clock::now();
  JointCalibration out;
  JointAccount account;
  Sigmas sigma;
  sigma.colour_px = std::max(0.05, in.cameras.colour.rms_reprojection_px);
  sigma.outline_px = std::max(0.05, in.cameras.extrinsics_rms_px);
  Round round;
  for (int r = 0; r < options.weighting_rounds; ++r) {
    round = FitRound(options, in, frames, sigma, b, &account.held);
    if (!round.summary.IsSolutionUsable())
      return Rejection{"joint_calibration", "the bundle adjustment failed: " + round.summary.message};
    // A kind with no observation (a board larger than its chessboard has
    // no outline) keeps its weight: nothing measured its scatter.
    const auto rescale = [&](double& s, const std::vector<ceres::ResidualBlockId>& kind) {
      if (!kind.empty()) s *= std::max(1e-3, RmsInSigmas(*round.problem, kind));
    };
    rescale(sigma.colour_px, round.kinds.colour);
    rescale(sigma.outline_px, round.kinds.outline);
    rescale(sigma.raw, round.kinds.depth);
    account.iterations += static_cast<int>(round.summary.iterations.size());
  }
  account.terms = {{"colour corners", "px", static_cast<int>(round.kinds.colour.size()), sigma.colour_px},
                   {"outline corners", "px", static_cast<int>(round.kinds.outline.size()), sigma.outline_px},
                   {"depth samples", "raw", static_cast<int>(round.kinds.depth.size()), sigma.raw}};
  // The covariance of the last round, whose weights the one before it measured.
  round = FitRound(options, in, frames, sigma, b, &account.held);
  account.iterations += static_cast<int>(round.summary.iterations.size());
  const Layout layout = EveryBlock(*round.problem, b);
  const auto covariance = ClusterRobustCovariance(*round.problem, round.kinds.all, round.kinds.pose, layout.blocks);
  if (!covariance) return Rejection{"joint_calibration", "the joint covariance could not be computed"};

  out.cameras = in.cameras;
  out.cameras.colour = FromBlocks(in.cameras.colour, b.colour_k, b.colour_lens);
  out.cameras.depth = FromBlocks(in.cameras.depth, b.depth_k, b.depth_lens);
  CameraSigmas(*covariance, layout, b.colour_k, b.colour_lens, out.cameras.colour);
  CameraSigmas(*covariance, layout, b.depth_k, b.depth_lens, out.cameras.depth);
  out.cameras.colour.rms_reprojection_px = sigma.colour_px;
  out.cameras.depth_from_colour = FromPose(b.rotation, b.translation);
  out.cameras.depth_edge_offset_px = b.edge_offset_px;
  if (in.cameras.depth_delay_s || b.DelayBlock() != &b.delay_s) out.cameras.depth_delay_s = *b.DelayBlock();
  out.cameras.extrinsics_rms_px = sigma.outline_px;
  if (auto at = layout.offset.find(b.translation); at != layout.offset.end())
    for (int i = 0; i < 3; ++i)
      out.cameras.extrinsics_translation_sigma_m[i] = std::sqrt((*covariance)(at->second + i, at->second + i));
  account.trades = EffectTrades(*covariance, layout, b);
  account.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.cameras.joint = account;
  for (std::size_t k = 0; k < b.model->Effects().size(); ++k)
    out.effect_parameters.push_back(b.model->EffectParameters(k));
  const SampleGradients gradients = DepthGradients(in, b, layout);
  out.depths = gradients.depth;
  DepthDirections(options, gradients, *covariance, out);
  return out;
}

void MoveSamples(const JointCalibration& joint, std::vector<PairedSample>& samples) {
  const Eigen::Isometry3d colour_from_depth = joint.cameras.depth_from_colour.inverse();
  for (std::size_t i = 0; i < samples.size() && i < joint.depths.size(); ++i) {
    PairedSample& s = samples[i];
    const Eigen::Vector2d xy = joint.cameras.depth.Undistort({s.u, s.v});
    s.x = xy.x(), s.y = xy.y();
    s.depth_m = joint.depths[i];
    s.in_colour = colour_from_depth * Eigen::Vector3d(s.x * s.depth_m, s.y * s.depth_m, s.depth_m);
    s.truth_sigma_m = joint.residual_sigma_m[i];
  }
}

bool JointOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .AtLeast(max_depth_samples, 100, "max_depth_samples")
      .AtLeast(max_iterations, 1, "max_iterations")
      .Positive(huber_sigmas, "huber_sigmas")
      .AtLeast(weighting_rounds, 1, "weighting_rounds")
      .AtLeast(max_directions, 1, "max_directions")
      .AtLeast(max_effect_parameters, 0, "max_effect_parameters")
      .AtLeast(hold_out_depth_samples, 100, "hold_out_depth_samples")
      .AtLeast(hold_out_iterations, 1, "hold_out_iterations")
      .Require(function_tolerance > 0 && function_tolerance < 1, "function_tolerance", "in (0, 1)")
      .Require(hold_out_function_tolerance > 0 && hold_out_function_tolerance < 1, "hold_out_function_tolerance",
               "in (0, 1)")
      .valid();
}

}  // namespace speckle::joint
