#include "lab/joint/joint_problem.h"

#include <algorithm>
#include <cmath>

#include "lab/fit/residual_blocks.h"
#include "lab/fit/tangent_form_manifold.h"
#include "lab/joint/camera_priors.h"
#include "lab/joint/chained_costs.h"
#include "lab/joint/joint_residuals.h"
#include "lab/joint/sample_raw_with_effects.h"
#include "stages/ceres_blocks.h"
#include "stages/outline_calibration.h"

namespace speckle::joint {
namespace {

std::array<double, 6> ToPose(const Eigen::Isometry3d& t) {
  const Eigen::AngleAxisd aa(t.linear());
  const Eigen::Vector3d r = aa.angle() * aa.axis();
  return {r.x(), r.y(), r.z(), t.translation().x(), t.translation().y(), t.translation().z()};
}

}  // namespace

Blocks::Blocks(const Blocks& other)
    : edge_offset_px(other.edge_offset_px),
      delay_s(other.delay_s),
      base(other.base),
      base_size(other.base_size),
      pose_values(other.pose_values),
      pose_of_frame(other.pose_of_frame),
      model(other.model ? std::make_unique<model::DepthModel>(*other.model) : nullptr) {
  std::copy(other.colour_k, other.colour_k + 4, colour_k),
      std::copy(other.colour_lens, other.colour_lens + 5, colour_lens);
  std::copy(other.depth_k, other.depth_k + 4, depth_k), std::copy(other.depth_lens, other.depth_lens + 5, depth_lens);
  std::copy(other.rotation, other.rotation + 3, rotation),
      std::copy(other.translation, other.translation + 3, translation);
  std::copy(other.billow, other.billow + 2, billow);
}

std::vector<double*> Blocks::EffectBlocks() {
  std::vector<double*> out;
  for (std::size_t k = 0; model && k < model->Effects().size(); ++k) out.push_back(model->EffectParameters(k).data());
  return out;
}

double* Blocks::DelayBlock() {
  for (std::size_t k = 0; model && k < model->Effects().size(); ++k)
    if (model->Effects()[k]->Name() == "capture_time_offset") return model->EffectParameters(k).data();
  return &delay_s;
}

double* Blocks::Pose(int frame) {
  const auto at = pose_of_frame.find(frame);
  return at == pose_of_frame.end() ? nullptr : pose_values[at->second].data();
}

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
  b.delay_s = in.cameras.depth_delay_s.value_or(0);
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

// Frames with a chessboard, an outline and samples: the ones that tie the cameras together.
std::vector<const BoardFrame*> UsableFrames(const JointInput& in) {
  std::map<int, int> samples_per_frame;
  for (const auto& s : in.samples) ++samples_per_frame[s.frame];
  std::vector<const BoardFrame*> out;
  for (const auto& f : in.frames)
    if (!f.colour_corners.empty() && samples_per_frame[f.frame] > 0) out.push_back(&f);
  return out;
}

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

Term MakeDepthSampleTerm(const JointInput& in, const Sigmas& sigma, Blocks& b, const PairedSample& s) {
  Term t;
  t.noise = sigma.raw * in.reading.UnitsPerRawStep(s.raw);
  t.blocks = {b.Pose(s.frame), b.rotation, b.translation, b.depth_k, b.depth_lens, b.base.data(), b.billow};
  const std::vector<double*> effects = b.EffectBlocks();
  t.blocks.insert(t.blocks.end(), effects.begin(), effects.end());
  const SampleRaw geometry(s.u, s.v, s.raw, t.noise, in.form);
  t.cost = new SampleRawWithEffects(geometry, b.base_size, b.model.get(), &s);
  return t;
}

std::vector<Term> ColourCornerTerms(const JointInput& in, const BoardFrame& f, const Sigmas& sigma, Blocks& b) {
  const auto points = in.board.InteriorCornerPoints();
  std::vector<Term> out;
  if (f.colour_corners.size() != points.size()) return out;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d on_board(points[i].x, points[i].y, points[i].z);
    const Eigen::Vector2d observed(f.colour_corners[i].x, f.colour_corners[i].y);
    out.push_back({new ColourCornerCost(ColourCorner(on_board, observed, sigma.colour_px)),
                   {b.Pose(f.frame), b.colour_k, b.colour_lens},
                   sigma.colour_px});
  }
  return out;
}

std::vector<Term> OutlineTerms(const JointInput& in, const BoardFrame& f, const Sigmas& sigma, Blocks& b) {
  const auto outline = OutlineCorners(in.board);
  std::vector<Term> out;
  if (!f.quad) return out;
  for (std::size_t c = 0; c < 4; ++c) {
    out.push_back(
        {new ceres::AutoDiffCostFunction<OutlineCorner, 2, 6, 3, 3, 4, 5, 1, 1>(
             new OutlineCorner(outline[c], f.board_velocity, f.quad->corners_px[c],
                               CornerOutward(*f.quad, static_cast<int>(c)), sigma.outline_px)),
         {b.Pose(f.frame), b.rotation, b.translation, b.depth_k, b.depth_lens, &b.edge_offset_px, b.DelayBlock()},
         sigma.outline_px});
  }
  return out;
}

namespace {

void AddTerms(std::vector<Term> terms, ceres::LossFunction* loss, int still_pose, ceres::Problem& problem,
              std::vector<ceres::ResidualBlockId>& kind, Kinds& kinds) {
  for (Term& t : terms) kinds.Add(kind, problem.AddResidualBlock(t.cost, loss, t.blocks), still_pose);
}

void AddDepthSamples(const JointOptions& options, const JointInput& in, const Sigmas& sigma,
                     const std::set<int>& held_out, ceres::LossFunction* loss, Blocks& b, ceres::Problem& problem,
                     Kinds& kinds) {
  const std::size_t step =
      std::max<std::size_t>(1, (in.samples.size() + static_cast<std::size_t>(options.max_depth_samples) - 1) /
                                   static_cast<std::size_t>(options.max_depth_samples));
  for (std::size_t i = 0; i < in.samples.size(); i += step) {
    const PairedSample& s = in.samples[i];
    double* pose = b.Pose(s.frame);
    if (!pose || !problem.HasParameterBlock(pose) || held_out.count(s.pose)) continue;
    const Term term = MakeDepthSampleTerm(in, sigma, b, s);
    kinds.Add(kinds.depth, problem.AddResidualBlock(term.cost, loss, term.blocks), s.pose);
  }
  const std::vector<double*> effects = b.EffectBlocks();
  if (kinds.depth.empty() || effects.empty()) return;
  // The effects' priors are information the fit used: its covariance counts them as independent of any pose.
  for (ceres::ResidualBlockId prior : fitting::ConstrainEffects(b.model->Definition(), *b.model, effects,
                                                                std::vector<bool>(effects.size(), false), problem))
    kinds.Add(kinds.prior, prior, -1);
}

// A camera's terms (`size` of them from `first` in its stddev order) held
// where the step that gave them held them (no standard deviation): what the
// data could not support there stays unsupported.
void HoldUnsupported(ceres::Problem& problem, double* block, int first, int size, const CameraIntrinsics& start,
                     const std::string& camera, std::vector<std::string>* held) {
  static const char* kNames[9] = {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"};
  std::vector<int> constant;
  for (int i = 0; i < size; ++i)
    if (!(start.stddev[static_cast<std::size_t>(first + i)] > 0)) constant.push_back(i);
  if (static_cast<int>(constant.size()) == size) {
    HoldConstant(problem, block);
  } else if (!constant.empty()) {
    problem.SetManifold(block, new ceres::SubsetManifold(size, constant));
  }
  for (int i : constant) held->push_back(camera + " " + kNames[first + i]);
}

// A camera the session gave without standard deviations is held exactly as
// the user asked (with them it is free within its prior: camera_priors.h).
bool GivenExactly(const CameraIntrinsics& c) {
  return std::all_of(c.stddev.begin(), c.stddev.end(), [](double s) { return !(s > 0); });
}

void HoldWhatIsNotFitted(const JointOptions& options, const JointInput& in, Blocks& b, ceres::Problem& problem,
                         std::vector<std::string>* held) {
  const CameraIntrinsics& colour = in.cameras.colour;
  const CameraIntrinsics& depth = in.cameras.depth;
  if (GivenExactly(colour)) {
    HoldConstant(problem, b.colour_k), HoldConstant(problem, b.colour_lens);
    held->push_back("colour camera (given)");
  } else {
    // A prior names its own exact terms (camera_priors.h).
    if (!in.cameras.colour_prior) HoldUnsupported(problem, b.colour_k, 0, 4, colour, "colour", held);
    HoldUnsupported(problem, b.colour_lens, 4, 5, colour, "colour", held);
  }
  if (GivenExactly(depth)) {
    // A depth camera given is the IR image's. The depth image is shifted
    // from the IR image by a few pixels (ROS kinect_calibration), which only
    // the principal point takes up exactly: held too, the extrinsics turned
    // toward the shift and reference_tilt took the rest (the hunt's given
    // depth_grid_offset row). So the depth image's principal point is fitted.
    HoldConstant(problem, b.depth_lens);
    problem.SetManifold(b.depth_k, new ceres::SubsetManifold(4, {0, 1}));
    held->push_back("depth camera fx, fy and lens (given; the depth image's principal point is fitted)");
  } else {
    if (!in.cameras.depth_prior) HoldUnsupported(problem, b.depth_k, 0, 4, depth, "depth", held);
    HoldUnsupported(problem, b.depth_lens, 4, 5, depth, "depth", held);
  }
  // The delay where a moving board showed it to the separate steps, or the model's own.
  if (b.DelayBlock() == &b.delay_s && !in.cameras.depth_delay_s && problem.HasParameterBlock(&b.delay_s))
    HoldConstant(problem, &b.delay_s);
  // Billowing is a disparity effect, and the model's own radial billow is that nuisance.
  const bool billow_in_model = std::any_of(in.effects.begin(), in.effects.end(),
                                           [](const model::EffectSpec& e) { return e.name == "radial_billow"; });
  if (in.reading.units() == DepthUnits::kMillimetre || billow_in_model || !options.billow_nuisance) {
    HoldConstant(problem, b.billow);
  } else {
    for (int i = 0; i < 2; ++i) BoundParameter(problem, b.billow, i, 0, 1e7);
  }
}

}  // namespace

Round FitRound(const JointOptions& options, const JointInput& in, const std::vector<const BoardFrame*>& frames,
               const Sigmas& sigma, Blocks& b, std::vector<std::string>* held, const std::set<int>& depth_held_out) {
  Round r;
  r.loss = std::make_unique<ceres::HuberLoss>(options.huber_sigmas);
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  r.problem = std::make_unique<ceres::Problem>(problem_options);
  for (const BoardFrame* f : frames)
    AddTerms(ColourCornerTerms(in, *f, sigma, b), r.loss.get(), f->pose, *r.problem, r.kinds.colour, r.kinds);
  for (const BoardFrame* f : frames)
    AddTerms(OutlineTerms(in, *f, sigma, b), r.loss.get(), f->pose, *r.problem, r.kinds.outline, r.kinds);
  AddDepthSamples(options, in, sigma, depth_held_out, r.loss.get(), b, *r.problem, r.kinds);
  held->clear();
  HoldWhatIsNotFitted(options, in, b, *r.problem, held);
  AddCameraPriors(in, b, *r.problem, r.kinds, held);
  // The tangent form steps where its valley toward the reciprocal form ends
  // (lab/fit/tangent_form_manifold.h): stepping in (c, k, b) every fold of
  // the tangent candidate crept to its iteration limit, and was judged there.
  if (in.form == model::BaseForm::kTangent && r.problem->HasParameterBlock(b.base.data()))
    r.problem->SetManifold(b.base.data(), new TangentFormManifold);
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_SCHUR;  // the poses eliminated, one 6-block each
  auto* ordering = new ceres::ParameterBlockOrdering;
  for (auto& pose : b.pose_values)
    if (r.problem->HasParameterBlock(pose.data())) ordering->AddElementToGroup(pose.data(), 0);
  for (double* block : {b.colour_k, b.colour_lens, b.depth_k, b.depth_lens, b.rotation, b.translation,
                        &b.edge_offset_px, &b.delay_s, b.billow, b.base.data()})
    if (r.problem->HasParameterBlock(block)) ordering->AddElementToGroup(block, 1);
  for (double* block : b.EffectBlocks())
    if (r.problem->HasParameterBlock(block)) ordering->AddElementToGroup(block, 1);
  solver.linear_solver_ordering.reset(ordering);
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = options.function_tolerance;
  // With bounds (the billow's, an effect's), Ceres follows each step with a
  // projected Armijo search, which by default evaluates the Jacobian at its
  // trial point for a cubic: as much again as the iteration's own. The
  // quadratic needs only the cost there (the gradient at the start is known).
  solver.line_search_interpolation_type = ceres::QUADRATIC;
  // One thread: the Schur complement summed in another order by another
  // thread moved the cameras in the fifth digit from run to run (the golden
  // regression tests demand the same numbers from the same session).
  solver.num_threads = 1;
  solver.dense_linear_algebra_library_type = ceres::EIGEN;  // a threaded BLAS sums in any order
  ceres::Solve(solver, r.problem.get(), &r.summary);
  return r;
}

void Layout::Add(ceres::Problem& problem, const double* block) {
  if (!problem.HasParameterBlock(block) || offset.count(block)) return;
  blocks.push_back(block);
  offset[block] = size;
  size += problem.ParameterBlockSize(block);
}

Layout EveryBlock(ceres::Problem& problem, Blocks& b) {
  Layout layout;
  for (auto& pose : b.pose_values) layout.Add(problem, pose.data());
  for (const double* block :
       std::array<const double*, 10>{b.colour_k, b.colour_lens, b.depth_k, b.depth_lens, b.rotation, b.translation,
                                     &b.edge_offset_px, &b.delay_s, b.billow, b.base.data()})
    layout.Add(problem, block);
  for (const double* block : b.EffectBlocks()) layout.Add(problem, block);
  return layout;
}

std::optional<TermGradient> EvaluateTerm(const Term& term, const Layout& layout) {
  const std::vector<int32_t>& sizes = term.cost->parameter_block_sizes();
  if (term.cost->num_residuals() != 1 || sizes.size() != term.blocks.size()) return std::nullopt;
  std::vector<std::vector<double>> jacobian(sizes.size());
  std::vector<double*> jacobians(sizes.size());
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    jacobian[k].assign(static_cast<std::size_t>(sizes[k]), 0.0);
    jacobians[k] = jacobian[k].data();
  }
  TermGradient out;
  if (!term.cost->Evaluate(term.blocks.data(), &out.value, jacobians.data())) return std::nullopt;
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    const auto where = layout.offset.find(term.blocks[k]);
    if (where == layout.offset.end()) continue;
    for (int j = 0; j < sizes[k]; ++j)
      out.gradient.push_back({where->second + j, jacobian[k][static_cast<std::size_t>(j)]});
  }
  return out;
}

}  // namespace speckle::joint
