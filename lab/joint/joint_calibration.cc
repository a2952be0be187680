#include "lab/joint/joint_calibration.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "lab/fit/residual_blocks.h"
#include "lab/joint/cluster_covariance.h"
#include "lab/joint/joint_residuals.h"
#include "lab/joint/sample_raw_with_effects.h"
#include "schemas/option_check.h"
#include "stages/ceres_blocks.h"
#include "stages/outline_calibration.h"

namespace speckle::joint {
namespace {

// Every parameter block of the joint problem.
struct Blocks {
  double colour_k[4], colour_lens[5], depth_k[4], depth_lens[5], rotation[3], translation[3];
  double edge_offset_px = 0;
  double billow[2] = {0, 0};
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
  std::vector<double*> EffectBlocks() {
    std::vector<double*> out;
    for (std::size_t k = 0; model && k < model->Effects().size(); ++k) out.push_back(model->EffectParameters(k).data());
    return out;
  }
  double* Pose(int frame) {
    const auto at = pose_of_frame.find(frame);
    return at == pose_of_frame.end() ? nullptr : pose_values[at->second].data();
  }
};

void ToBlocks(const CameraIntrinsics& c, double* k, double* lens) {
  const cv::Matx33d& m = c.camera_matrix;
  k[0] = m(0, 0), k[1] = m(1, 1), k[2] = m(0, 2), k[3] = m(1, 2);
  std::copy(c.distortion.begin(), c.distortion.end(), lens);
}

CameraIntrinsics FromBlocks(CameraIntrinsics c, const double* k, const double* lens) {
  c.camera_matrix = cv::Matx33d(k[0], 0, k[2], 0, k[1], k[3], 0, 0, 1);
  std::copy(lens, lens + 5, c.distortion.begin());
  return c;
}

std::array<double, 6> ToPose(const Eigen::Isometry3d& t) {
  const Eigen::AngleAxisd aa(t.linear());
  const Eigen::Vector3d r = aa.angle() * aa.axis();
  return {r.x(), r.y(), r.z(), t.translation().x(), t.translation().y(), t.translation().z()};
}

Eigen::Isometry3d FromPose(const double* rotation, const double* translation) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d r(rotation[0], rotation[1], rotation[2]);
  if (r.norm() > 0) t.linear() = Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(translation[0], translation[1], translation[2]);
  return t;
}

Blocks StartBlocks(const JointInput& in) {
  Blocks b;
  ToBlocks(in.cameras.colour, b.colour_k, b.colour_lens);
  ToBlocks(in.cameras.depth, b.depth_k, b.depth_lens);
  const auto extrinsics = ToPose(in.cameras.depth_from_colour);
  std::copy(extrinsics.begin(), extrinsics.begin() + 3, b.rotation);
  std::copy(extrinsics.begin() + 3, extrinsics.end(), b.translation);
  b.edge_offset_px = in.cameras.depth_edge_offset_px.value_or(0);
  const std::vector<double>& base = model::Info(in.form).initial;
  b.base_size = base.size();
  std::copy(base.begin(), base.end(), b.base.begin());
  b.model = std::make_unique<model::DepthModel>(model::ModelDefinition{in.form, in.effects});
  b.pose_values.reserve(in.frames.size());
  for (const auto& f : in.frames) {
    if (b.pose_of_frame.count(f.frame)) continue;
    b.pose_of_frame[f.frame] = b.pose_values.size();
    b.pose_values.push_back(ToPose(f.colour_from_board));
  }
  return b;
}

// Each kind's noise (its unit), the weights of the next round.
struct Sigmas {
  double colour_px = 0.3, outline_px = 0.3, raw = 1.0;
};

// The residual blocks of one kind, to measure that kind's scatter.
struct Kinds {
  std::vector<ceres::ResidualBlockId> colour, outline, depth;
  std::vector<ceres::ResidualBlockId> all;
  std::vector<int> pose;  // each of `all`'s still pose
  void Add(std::vector<ceres::ResidualBlockId>& kind, ceres::ResidualBlockId id, int still_pose) {
    kind.push_back(id), all.push_back(id), pose.push_back(still_pose);
  }
};

// Frames with a chessboard, an outline and samples: the ones that tie the cameras together.
std::vector<const BoardFrame*> UsableFrames(const JointInput& in) {
  std::map<int, int> samples_per_frame;
  for (const auto& s : in.samples) ++samples_per_frame[s.frame];
  std::vector<const BoardFrame*> out;
  for (const auto& f : in.frames)
    if (f.quad && !f.colour_corners.empty() && samples_per_frame[f.frame] > 0) out.push_back(&f);
  return out;
}

void AddColourCorners(const JointInput& in, const std::vector<const BoardFrame*>& frames, const Sigmas& sigma,
                      ceres::LossFunction* loss, Blocks& b, ceres::Problem& problem, Kinds& kinds) {
  const auto points = in.board.InteriorCornerPoints();
  for (const BoardFrame* f : frames) {
    if (f->colour_corners.size() != points.size()) continue;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d on_board(points[i].x, points[i].y, points[i].z);
      const Eigen::Vector2d observed(f->colour_corners[i].x, f->colour_corners[i].y);
      kinds.Add(kinds.colour,
                problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ColourCorner, 2, 6, 4, 5>(
                                             new ColourCorner(on_board, observed, sigma.colour_px)),
                                         loss, b.Pose(f->frame), b.colour_k, b.colour_lens),
                f->pose);
    }
  }
}

void AddOutlines(const JointInput& in, const std::vector<const BoardFrame*>& frames, const Sigmas& sigma,
                 ceres::LossFunction* loss, Blocks& b, ceres::Problem& problem, Kinds& kinds) {
  const auto outline = OutlineCorners(in.board);
  const double delay = in.cameras.depth_delay_s.value_or(0);
  for (const BoardFrame* f : frames) {
    for (int c = 0; c < 4; ++c) {
      kinds.Add(
          kinds.outline,
          problem.AddResidualBlock(
              new ceres::AutoDiffCostFunction<OutlineCorner, 2, 6, 3, 3, 4, 5, 1>(new OutlineCorner(
                  outline[static_cast<std::size_t>(c)], delay * f->board_velocity,
                  f->quad->corners_px[static_cast<std::size_t>(c)], CornerOutward(*f->quad, c), sigma.outline_px)),
              loss, b.Pose(f->frame), b.rotation, b.translation, b.depth_k, b.depth_lens, &b.edge_offset_px),
          f->pose);
    }
  }
}

void AddDepthSamples(const JointOptions& options, const JointInput& in, const Sigmas& sigma, ceres::LossFunction* loss,
                     Blocks& b, ceres::Problem& problem, Kinds& kinds) {
  const std::size_t step =
      std::max<std::size_t>(1, (in.samples.size() + static_cast<std::size_t>(options.max_depth_samples) - 1) /
                                   static_cast<std::size_t>(options.max_depth_samples));
  const std::vector<double*> effects = b.EffectBlocks();
  for (std::size_t i = 0; i < in.samples.size(); i += step) {
    const PairedSample& s = in.samples[i];
    double* pose = b.Pose(s.frame);
    if (!pose || !problem.HasParameterBlock(pose)) continue;
    const double noise = sigma.raw * in.reading.UnitsPerRawStep(s.raw);
    std::vector<double*> blocks = {pose, b.rotation, b.translation, b.depth_k, b.depth_lens, b.base.data(), b.billow};
    blocks.insert(blocks.end(), effects.begin(), effects.end());
    auto* cost =
        new SampleRawWithEffects(new SampleRaw(s.u, s.v, s.raw, noise, in.form), b.base_size, b.model.get(), &s);
    kinds.Add(kinds.depth, problem.AddResidualBlock(cost, loss, blocks), s.pose);
  }
  if (!kinds.depth.empty() && !effects.empty())
    fitting::ConstrainEffects(b.model->Definition(), *b.model, effects, std::vector<bool>(effects.size(), false),
                              problem);
}

// A lens's terms held where the separate step held them (no standard
// deviation): what the data could not support there stays unsupported.
void HoldLens(ceres::Problem& problem, double* lens, const CameraIntrinsics& start, const std::string& camera,
              std::vector<std::string>* held) {
  static const char* kNames[5] = {"k1", "k2", "p1", "p2", "k3"};
  std::vector<int> constant;
  for (int i = 0; i < 5; ++i)
    if (!(start.stddev[static_cast<std::size_t>(4 + i)] > 0)) constant.push_back(i);
  if (constant.size() == 5) {
    HoldConstant(problem, lens);
  } else if (!constant.empty()) {
    problem.SetManifold(lens, new ceres::SubsetManifold(5, constant));
  }
  for (int i : constant) held->push_back(camera + " " + kNames[i]);
}

// A camera the session gave (no standard deviations) is held exactly as the user asked.
bool GivenExactly(const CameraIntrinsics& c) {
  return std::all_of(c.stddev.begin(), c.stddev.begin() + 4, [](double s) { return !(s > 0); });
}

void HoldWhatIsNotFitted(const JointInput& in, Blocks& b, ceres::Problem& problem, std::vector<std::string>* held) {
  const CameraIntrinsics& colour = in.cameras.colour;
  const CameraIntrinsics& depth = in.cameras.depth;
  if (GivenExactly(colour)) {
    HoldConstant(problem, b.colour_k), HoldConstant(problem, b.colour_lens);
    held->push_back("colour camera (given)");
  } else {
    HoldLens(problem, b.colour_lens, colour, "colour", held);
  }
  if (GivenExactly(depth)) {
    HoldConstant(problem, b.depth_k), HoldConstant(problem, b.depth_lens);
    held->push_back("depth camera (given)");
  } else {
    HoldLens(problem, b.depth_lens, depth, "depth", held);
  }
  // Billowing is a disparity effect, and the model's own radial billow is that nuisance.
  const bool billow_in_model = std::any_of(in.effects.begin(), in.effects.end(),
                                           [](const model::EffectSpec& e) { return e.name == "radial_billow"; });
  if (in.reading.units() == DepthUnits::kMillimetre || billow_in_model) {
    HoldConstant(problem, b.billow);
  } else {
    for (int i = 0; i < 2; ++i) BoundParameter(problem, b.billow, i, 0, 1e7);
  }
}

// A kind's RMS residual (per coordinate) in units of the sigma it was weighed with.
double RmsInSigmas(ceres::Problem& problem, const std::vector<ceres::ResidualBlockId>& ids) {
  if (ids.empty()) return 0;
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.residual_blocks = ids;
  evaluate.apply_loss_function = false;
  std::vector<double> residuals;
  problem.Evaluate(evaluate, nullptr, &residuals, nullptr, nullptr);
  double sum = 0;
  for (double r : residuals) sum += r * r;
  return std::sqrt(sum / static_cast<double>(residuals.size()));
}

// One weighted fit from the blocks where they are; `problem` holds it after.
struct Round {
  std::unique_ptr<ceres::LossFunction> loss;  // outlives the problem that uses it
  std::unique_ptr<ceres::Problem> problem;
  Kinds kinds;
  ceres::Solver::Summary summary;
};

Round FitRound(const JointOptions& options, const JointInput& in, const std::vector<const BoardFrame*>& frames,
               const Sigmas& sigma, Blocks& b, std::vector<std::string>* held) {
  Round r;
  r.loss = std::make_unique<ceres::HuberLoss>(options.huber_sigmas);
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  r.problem = std::make_unique<ceres::Problem>(problem_options);
  AddColourCorners(in, frames, sigma, r.loss.get(), b, *r.problem, r.kinds);
  AddOutlines(in, frames, sigma, r.loss.get(), b, *r.problem, r.kinds);
  AddDepthSamples(options, in, sigma, r.loss.get(), b, *r.problem, r.kinds);
  held->clear();
  HoldWhatIsNotFitted(in, b, *r.problem, held);
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_SCHUR;  // the poses eliminated, one 6-block each
  auto* ordering = new ceres::ParameterBlockOrdering;
  for (auto& pose : b.pose_values)
    if (r.problem->HasParameterBlock(pose.data())) ordering->AddElementToGroup(pose.data(), 0);
  for (double* block : {b.colour_k, b.colour_lens, b.depth_k, b.depth_lens, b.rotation, b.translation,
                        &b.edge_offset_px, b.billow, b.base.data()})
    if (r.problem->HasParameterBlock(block)) ordering->AddElementToGroup(block, 1);
  for (double* block : b.EffectBlocks())
    if (r.problem->HasParameterBlock(block)) ordering->AddElementToGroup(block, 1);
  solver.linear_solver_ordering.reset(ordering);
  solver.max_num_iterations = options.max_iterations;
  // One thread: the Schur complement summed in another order by another
  // thread moved the cameras in the fifth digit from run to run (the golden
  // regression tests demand the same numbers from the same session).
  solver.num_threads = 1;
  solver.dense_linear_algebra_library_type = ceres::EIGEN;  // a threaded BLAS sums in any order
  ceres::Solve(solver, r.problem.get(), &r.summary);
  return r;
}

// Where each block starts in the covariance's order.
struct Layout {
  std::vector<const double*> blocks;
  std::map<const double*, int> offset;
  int size = 0;
  void Add(ceres::Problem& problem, const double* block) {
    if (!problem.HasParameterBlock(block)) return;
    blocks.push_back(block);
    offset[block] = size;
    size += problem.ParameterBlockSize(block);
  }
};

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

// A camera's standard deviations from the covariance (zero for terms held).
void CameraSigmas(const Eigen::MatrixXd& covariance, const Layout& layout, const double* k, const double* lens,
                  CameraIntrinsics& camera) {
  camera.stddev.fill(0);
  if (auto at = layout.offset.find(k); at != layout.offset.end())
    for (int i = 0; i < 4; ++i)
      camera.stddev[static_cast<std::size_t>(i)] = std::sqrt(covariance(at->second + i, at->second + i));
  if (auto at = layout.offset.find(lens); at != layout.offset.end())
    for (int i = 0; i < 5; ++i)
      camera.stddev[static_cast<std::size_t>(4 + i)] =
          std::sqrt(std::max(0.0, covariance(at->second + i, at->second + i)));
}

}  // namespace

StageResult<JointCalibration> RunJointCalibration(const JointOptions& options, const JointInput& in) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("joint calibration's options: " + why);
  const auto frames = UsableFrames(in);
  if (frames.size() < 3)
    return Rejection{"joint_calibration", std::to_string(frames.size()) +
                                              " board frames hold a chessboard, an outline and samples; it needs 3"};
  Blocks b = StartBlocks(in);
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
    sigma.colour_px *= std::max(1e-3, RmsInSigmas(*round.problem, round.kinds.colour));
    sigma.outline_px *= std::max(1e-3, RmsInSigmas(*round.problem, round.kinds.outline));
    sigma.raw *= std::max(1e-3, RmsInSigmas(*round.problem, round.kinds.depth));
    account.iterations += static_cast<int>(round.summary.iterations.size());
  }
  account.terms = {{"colour corners", "px", static_cast<int>(round.kinds.colour.size()), sigma.colour_px},
                   {"outline corners", "px", static_cast<int>(round.kinds.outline.size()), sigma.outline_px},
                   {"depth samples", "raw", static_cast<int>(round.kinds.depth.size()), sigma.raw}};
  // The covariance of the last round, whose weights the one before it measured.
  round = FitRound(options, in, frames, sigma, b, &account.held);
  account.iterations += static_cast<int>(round.summary.iterations.size());
  Layout layout;
  for (auto& pose : b.pose_values) layout.Add(*round.problem, pose.data());
  // Every free block, so that each sigma counts what the others leave
  // free (the base form trades against the extrinsics' depth).
  for (const double* block :
       std::array<const double*, 9>{b.colour_k, b.colour_lens, b.depth_k, b.depth_lens, b.rotation, b.translation,
                                    &b.edge_offset_px, b.billow, b.base.data()})
    layout.Add(*round.problem, block);
  for (const double* block : b.EffectBlocks()) layout.Add(*round.problem, block);
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
  out.cameras.extrinsics_rms_px = sigma.outline_px;
  if (auto at = layout.offset.find(b.translation); at != layout.offset.end())
    for (int i = 0; i < 3; ++i)
      out.cameras.extrinsics_translation_sigma_m[i] = std::sqrt((*covariance)(at->second + i, at->second + i));
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
      .valid();
}

}  // namespace speckle::joint
