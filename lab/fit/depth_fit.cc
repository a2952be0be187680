#include "lab/fit/depth_fit.h"

#include <ceres/ceres.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <set>

#include "lab/fit/tangent_form_manifold.h"
#include "stages/ceres_blocks.h"
#include "stages/step_clock.h"

namespace speckle {
namespace {

// A sample's weight in the fit: 1, or for a millimetre reading (1 m / z)^2,
// z its reading (see DepthFitOptions::millimetre_readings).
double ReadingWeight(const DepthFitOptions& options, const PairedSample& s) {
  if (!options.millimetre_readings || !(s.raw > 0)) return 1;
  const double z_m = s.raw / 1000;
  return 1 / (z_m * z_m);
}

// measured raw - (base_form^-1(true depth) + sum of effect offsets), with
// the base form differentiated by autodiff and each effect giving its own
// gradient (analytic, or autodiff over its own parameters only). An effect
// with a support (see SplitEffects) has one block per parameter, and the
// residual holds only the blocks of the parameters its sample reaches.
class ComposedResidual : public ceres::CostFunction {
 public:
  // depth_shift: the true depth's change under each camera perturbation; when
  // given, their weights are a last parameter block (camera freedom). The
  // sample must outlive the residual: it is read at each evaluation rather
  // than copied (a 2000-frame session's 316,000 residuals held 33 MB of
  // copied covariates). support: per effect, the parameters this sample
  // reaches, each its own block; empty: the effect's whole block.
  // weight: the residual's (ReadingWeight).
  ComposedResidual(const model::DepthModel* model, const PairedSample* sample, double depth_m, double weight,
                   std::vector<double> depth_shift = {}, std::vector<std::vector<int>> support = {})
      : model_(model),
        sample_(sample),
        depth_m_(depth_m),
        weight_(weight),
        depth_shift_(std::move(depth_shift)),
        support_(std::move(support)) {
    support_.resize(model->Effects().size());
    set_num_residuals(1);
    std::vector<int>& sizes = *mutable_parameter_block_sizes();
    sizes.push_back(static_cast<int>(model->Base().size()));
    for (std::size_t k = 0; k < model->Effects().size(); ++k) {
      if (support_[k].empty())
        sizes.push_back(static_cast<int>(model->EffectParameters(k).size()));
      else
        sizes.insert(sizes.end(), support_[k].size(), 1);
    }
    if (!depth_shift_.empty()) sizes.push_back(static_cast<int>(depth_shift_.size()));
    RequireNonEmptyBlocks(parameter_block_sizes(), "depth model residual");
  }

  bool Evaluate(double const* const* blocks, double* residual, double** jacobians) const override {
    // The base form's parameters, then the depth (for the camera freedom).
    constexpr int kDepth = model::kMaxBaseParameters;
    using BaseJet = ceres::Jet<double, kDepth + 1>;
    const int base_size = parameter_block_sizes()[0];
    const std::size_t shift_block = parameter_block_sizes().size() - 1;
    double depth = depth_m_;
    for (std::size_t k = 0; k < depth_shift_.size(); ++k) depth += blocks[shift_block][k] * depth_shift_[k];
    std::array<BaseJet, model::kMaxBaseParameters> base;
    for (int i = 0; i < base_size; ++i) base[i] = BaseJet(blocks[0][i], i);
    const BaseJet predicted = model::RawFromDepth(model_->Definition().form, base.data(), BaseJet(depth, kDepth));
    if (jacobians && !depth_shift_.empty() && jacobians[shift_block])
      for (std::size_t k = 0; k < depth_shift_.size(); ++k)
        jacobians[shift_block][k] = -predicted.v[kDepth] * depth_shift_[k];
    double offset = 0;
    const model::Covariates c = model_->Effects().empty() ? model::Covariates{} : FitCovariatesOf(*sample_);
    for (std::size_t k = 0, b = 1; k < model_->Effects().size(); ++k) {
      if (support_[k].empty()) {
        offset += EffectOffset(k, c, blocks[b], jacobians ? jacobians[b] : nullptr);
        ++b;
      } else {
        offset += SupportedEffectOffset(k, c, blocks + b, jacobians ? jacobians + b : nullptr);
        b += support_[k].size();
      }
    }
    residual[0] = sample_->raw - predicted.a - offset;
    if (jacobians && jacobians[0])
      for (int i = 0; i < base_size; ++i) jacobians[0][i] = -predicted.v[i];
    if (weight_ != 1) Weigh(residual, jacobians);
    return std::isfinite(residual[0]);
  }

 private:
  // Effect k's offset from its whole block, its negated gradient into `gradient` when asked.
  double EffectOffset(std::size_t k, const model::Covariates& c, const double* p, double* gradient) const {
    const model::Effect& effect = *model_->Effects()[k];
    if (const double* terms = LinearTerms(k, c)) {
      const std::size_t n = effect.Parameters().size();
      for (std::size_t i = 0; gradient && i < n; ++i) gradient[i] = -terms[i + 1];
      return model::LinearOffset(terms, p, n);
    }
    if (!gradient) return effect.RawOffset(p, c);
    const double offset = effect.RawOffset(p, c, gradient);
    for (std::size_t i = 0; i < effect.Parameters().size(); ++i) gradient[i] = -gradient[i];
    return offset;
  }

  // Effect k's offset from the one-parameter blocks of its support. A
  // sample whose support is every parameter (Support gave -1) is evaluated
  // as one whole block.
  double SupportedEffectOffset(std::size_t k, const model::Covariates& c, double const* const* blocks,
                               double** jacobians) const {
    thread_local std::vector<double> values, gradient;
    const std::size_t n = support_[k].size();
    values.resize(n), gradient.resize(n);
    for (std::size_t j = 0; j < n; ++j) values[j] = blocks[j][0];
    double* g = jacobians ? gradient.data() : nullptr;
    double offset = 0;
    if (n == model_->EffectParameters(k).size()) {
      offset = EffectOffset(k, c, values.data(), g);  // the gradient negated
    } else {
      offset = model_->Effects()[k]->RawOffsetOnSupport(values.data(), c, g);
      for (std::size_t j = 0; g && j < n; ++j) g[j] = -g[j];
    }
    for (std::size_t j = 0; g && j < n; ++j)
      if (jacobians[j]) jacobians[j][0] = g[j];
    return offset;
  }

  // Effect k's terms at this sample when it is linear in its parameters,
  // asked once: the sample never changes, and a formula effect's lookup at
  // every evaluation was a fifth of a formula refit's time.
  const double* LinearTerms(std::size_t k, const model::Covariates& c) const {
    if (linear_terms_.empty()) {
      linear_terms_.resize(model_->Effects().size());
      for (std::size_t e = 0; e < linear_terms_.size(); ++e)
        if (support_[e].empty()) linear_terms_[e] = model_->Effects()[e]->LinearTerms(c);
    }
    return linear_terms_[k];
  }

  // The residual and every block's derivatives times the weight.
  void Weigh(double* residual, double** jacobians) const {
    residual[0] *= weight_;
    for (std::size_t b = 0; jacobians && b < parameter_block_sizes().size(); ++b)
      for (int i = 0; jacobians[b] && i < parameter_block_sizes()[b]; ++i) jacobians[b][i] *= weight_;
  }

  const model::DepthModel* model_;
  const PairedSample* sample_;  // its covariates are what the effects see (raw: see PairedSample::fit_raw)
  double depth_m_;
  double weight_;
  std::vector<double> depth_shift_;
  std::vector<std::vector<int>> support_;
  mutable std::vector<const double*> linear_terms_;  // per effect, null when not linear (LinearTerms)
};

// Weak priors on an effect's parameters: (p - initial) / prior_sigma each.
class PriorCost : public ceres::CostFunction {
 public:
  explicit PriorCost(const std::vector<model::EffectParameter>& parameters) : parameters_(parameters) {
    set_num_residuals(static_cast<int>(parameters.size()));
    mutable_parameter_block_sizes()->push_back(static_cast<int>(parameters.size()));
  }
  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    const std::size_t n = parameters_.size();
    for (std::size_t i = 0; i < n; ++i) {
      const double sigma = parameters_[i].prior_sigma;
      residuals[i] = sigma > 0 ? (p[0][i] - parameters_[i].initial) / sigma : 0.0;
      if (jacobians && jacobians[0])
        for (std::size_t j = 0; j < n; ++j) jacobians[0][i * n + j] = i == j && sigma > 0 ? 1 / sigma : 0.0;
    }
    return true;
  }

 private:
  std::vector<model::EffectParameter> parameters_;
};

// The cameras free to move within their uncertainty (see
// DepthFitOptions::camera_freedom_sigma): perturbations are indexed like the
// samples from `first`.
struct CameraFreedom {
  const DepthPerturbations* perturbations = nullptr;
  const PairedSample* first = nullptr;
  double bound_sigma = 0;
};

struct Solved {
  std::unique_ptr<model::DepthModel> model;
  std::vector<double> camera_shift;  // one weight per perturbation (camera freedom)
  bool converged = false;
  // False when Ceres failed (e.g. "Residual and Jacobian evaluation failed")
  // or left a parameter not finite: nothing may be read from such a fit,
  // least of all its covariance (Eigen's SVD of a NaN Jacobian crashes).
  bool usable = false;
  std::string report;
  // One Huber loss for every residual, declared before the problem that
  // uses it so that it outlives it (one each cost 10 MB at 316,000 samples).
  std::unique_ptr<ceres::LossFunction> loss;
  std::unique_ptr<ceres::Problem> problem;
  std::vector<double*> blocks;
};

// Which effects get one Ceres block per parameter: in a large model, those
// that say which parameters each sample reaches (effect.h's Support).
std::vector<bool> SplitEffects(const DepthFitOptions& options, const model::DepthModel& m) {
  std::vector<bool> split(m.Effects().size(), false);
  if (!options.split_by_support || m.Flat().size() < options.sparse_from_parameters) return split;
  for (std::size_t k = 0; k < split.size(); ++k) split[k] = m.Effects()[k]->GivesSupport();
  return split;
}

// Per effect, the parameters sample s reaches (empty for an effect kept
// whole; every parameter where Support gives -1).
std::vector<std::vector<int>> SupportOf(const model::DepthModel& m, const std::vector<bool>& split,
                                        const PairedSample& s) {
  std::vector<std::vector<int>> support(split.size());
  const model::Covariates c = FitCovariatesOf(s);
  for (std::size_t k = 0; k < split.size(); ++k) {
    if (!split[k]) continue;
    std::vector<int>& indices = support[k];
    indices.resize(m.EffectParameters(k).size());
    const int n = m.Effects()[k]->Support(c, indices.data());
    if (n < 0)
      std::iota(indices.begin(), indices.end(), 0);
    else
      indices.resize(static_cast<std::size_t>(n));
  }
  return support;
}

// Samples whose residuals hold the same blocks, evaluated as one Ceres
// residual block of one row each. Ceres' cost per residual block (its
// evaluation bookkeeping, the problem's construction and teardown, a row
// block's products in J^T J) was a third of a 60-term formula refit's CPU
// with one block per sample. A loss applies to a block's whole squared
// norm, so with the Huber loss each sample stays its own block.
class ResidualBatch : public ceres::CostFunction {
 public:
  explicit ResidualBatch(std::vector<std::unique_ptr<ComposedResidual>> rows) : rows_(std::move(rows)) {
    set_num_residuals(static_cast<int>(rows_.size()));
    *mutable_parameter_block_sizes() = rows_.front()->parameter_block_sizes();
  }

  bool Evaluate(double const* const* blocks, double* residuals, double** jacobians) const override {
    const std::vector<int>& sizes = parameter_block_sizes();
    thread_local std::vector<double*> row_jacobians;
    row_jacobians.resize(sizes.size());
    for (std::size_t i = 0; i < rows_.size(); ++i) {
      for (std::size_t b = 0; jacobians && b < sizes.size(); ++b)
        row_jacobians[b] = jacobians[b] ? jacobians[b] + i * static_cast<std::size_t>(sizes[b]) : nullptr;
      if (!rows_[i]->Evaluate(blocks, residuals + i, jacobians ? row_jacobians.data() : nullptr)) return false;
    }
    return true;
  }

 private:
  std::vector<std::unique_ptr<ComposedResidual>> rows_;
};

// One row per sample, holding the blocks it reaches, in batches of samples
// that reach the same blocks (ResidualBatch). Returns whether some sample
// reaches every parameter of a split effect.
bool AddSampleResiduals(const DepthFitOptions& options, const std::vector<const PairedSample*>& samples,
                        const std::vector<double>* depths, const CameraFreedom* freedom, const std::vector<bool>& split,
                        Solved& out) {
  constexpr std::size_t kBatchRows = 64;
  const std::size_t batch_rows = out.loss ? 1 : kBatchRows;
  const model::DepthModel& m = *out.model;
  bool dense_row = false;
  std::map<std::vector<double*>, std::vector<std::unique_ptr<ComposedResidual>>> pending;
  const auto add = [&](const std::vector<double*>& blocks, std::vector<std::unique_ptr<ComposedResidual>>& rows) {
    out.problem->AddResidualBlock(new ResidualBatch(std::move(rows)), out.loss.get(), blocks);
    rows.clear();
  };
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const PairedSample& s = *samples[i];
    std::vector<double> shift;
    if (freedom) {
      const auto index = static_cast<std::size_t>(samples[i] - freedom->first);
      for (const auto& moved : *freedom->perturbations) shift.push_back(moved[index] - s.depth_m);
    }
    std::vector<std::vector<int>> support = SupportOf(m, split, s);
    std::vector<double*> blocks{out.blocks[0]};
    for (std::size_t k = 0; k < split.size(); ++k) {
      if (!split[k]) blocks.push_back(out.blocks[k + 1]);
      for (int j : support[k]) blocks.push_back(out.blocks[k + 1] + j);
      dense_row = dense_row || (split[k] && support[k].size() == m.EffectParameters(k).size());
    }
    if (freedom) blocks.push_back(out.camera_shift.data());
    auto& rows = pending[blocks];
    rows.push_back(std::make_unique<ComposedResidual>(&m, &s, depths ? (*depths)[i] : s.depth_m,
                                                      ReadingWeight(options, s), std::move(shift), std::move(support)));
    if (rows.size() == batch_rows) add(blocks, rows);
  }
  for (auto& [blocks, rows] : pending)
    if (!rows.empty()) add(blocks, rows);
  return dense_row;
}

// Frozen effects held, priors and bounds set: on the whole block, or on each
// parameter's block of a split effect.
void ConstrainEffects(const model::ModelDefinition& definition, const std::vector<bool>& split, Solved& out) {
  const model::DepthModel& m = *out.model;
  for (std::size_t k = 0; k < m.Effects().size(); ++k) {
    const auto& parameters = m.Effects()[k]->Parameters();
    const int blocks = split[k] ? static_cast<int>(parameters.size()) : 1;
    for (int b = 0; b < blocks; ++b) {
      double* block = out.blocks[k + 1] + b;
      if (definition.effects[k].frozen) {
        HoldConstant(*out.problem, block);
        continue;
      }
      const auto first = parameters.begin() + b;
      const std::vector<model::EffectParameter> own(first, split[k] ? first + 1 : parameters.end());
      bool prior = false;
      for (const auto& p : own) prior = prior || p.prior_sigma > 0;
      if (prior) out.problem->AddResidualBlock(new PriorCost(own), nullptr, block);
      for (std::size_t i = 0; i < own.size(); ++i)
        BoundParameter(*out.problem, block, static_cast<int>(i), own[i].lower, own[i].upper);
    }
  }
}

// sparse_effect: some effect gives its samples' support (effect.h), so its
// Jacobian is mostly zeros; any_split: some effect has a block per
// parameter; dense_row: some sample reaches all of them.
ceres::Solver::Options SolverOptions(const DepthFitOptions& options, std::size_t parameters, bool sparse_effect,
                                     bool any_split, bool dense_row) {
  ceres::Solver::Options solver;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = 1e-10;
  solver.parameter_tolerance = 1e-12;
  // With bounds on any parameter, Ceres' trust region follows every step
  // with a projected Armijo line search that evaluates the cost and its
  // gradient again (a quarter of a refit's time). The step is projected
  // onto the bounds anyway, and Ceres itself calls that search "not
  // terribly effective" (its issue 187): a dense model's trust region alone
  // decides. The large fields below keep it: without it a pattern's split
  // and one-block fits ended up to 3 sigma apart in its flat valley
  // (DepthFit.SplitBlocksMatchOneBlockPerEffect, 0.5 sigma with it).
  // A model this small (a base form and a few effects) solves fastest dense.
  // A B-spline field's samples each reach 16 of its hundreds of controls:
  // dense, forming J^T J costs samples x parameters^2 per iteration (the 354
  // controls of disparity_pattern spent 9 of a run's 19 s there). With each
  // control its own block and each sample holding only those it reaches, the
  // sparsity is known before the solve and a sparse Cholesky costs samples x
  // 18^2. A large effect that gives no support keeps one block, whose zeros
  // Ceres' dynamic sparsity drops at each evaluation: slower, as it writes
  // and checks every column of every row (the pattern candidate of a
  // 60-frame session: 19.5 s that way, 7.1 s split, in the same loaded hour).
  // A large model without such an effect (a 60-term formula) is dense, and
  // solves dense: the sparse path took 7.3 s where dense took 2.4 s (README).
  if (parameters >= options.sparse_from_parameters && sparse_effect) {
    solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    solver.dynamic_sparsity = !any_split;
    // Dogleg reaches the same optimum in fewer iterations here (Herrera's
    // undistorted pattern fit: 39 instead of 51, held out unchanged to 1e-6).
    solver.trust_region_strategy_type = ceres::DOGLEG;
    // A sample that reaches every control (a B-spline's last span, whose
    // control is minus the sum of the others) costs J^T J parameters^2
    // product terms: 120 such samples took a 770-parameter fit from 1 s to
    // 60 s, sorting them. Conjugate gradients on the normal equations never
    // form J^T J (the same fit in 10 s, ending within 1e-5 of its cost).
    if (dense_row) {
      solver.linear_solver_type = ceres::CGNR;
      solver.preconditioner_type = ceres::JACOBI;
      solver.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;  // dogleg needs a factorization
      solver.eta = 1e-4;
      solver.max_linear_solver_iterations = 2000;
    }
  } else {
    solver.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
    solver.max_num_line_search_step_size_iterations = 0;  // no line search: see above
  }
  return solver;
}

// start: flat parameters to begin from (the full fit's, for the camera
// refits: they land near it in a few iterations instead of a few dozen).
Solved Solve(const DepthFitOptions& options, const model::ModelDefinition& definition,
             const std::vector<const PairedSample*>& samples, const std::vector<double>* depths = nullptr,
             const std::vector<double>* start = nullptr, const CameraFreedom* freedom = nullptr) {
  Solved out;
  out.model = std::make_unique<model::DepthModel>(definition);
  model::DepthModel& m = *out.model;
  if (start) m.SetFlat(*start);
  if (options.huber_raw > 0) out.loss = std::make_unique<ceres::HuberLoss>(options.huber_raw);
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  out.problem = std::make_unique<ceres::Problem>(problem_options);
  out.blocks.push_back(m.Base().data());
  for (std::size_t k = 0; k < m.Effects().size(); ++k) out.blocks.push_back(m.EffectParameters(k).data());
  // A split effect's blocks are added up front: a parameter no sample
  // reaches is still held, bounded and given its prior.
  const std::vector<bool> split = SplitEffects(options, m);
  for (std::size_t k = 0; k < split.size(); ++k)
    for (std::size_t i = 0; split[k] && i < m.EffectParameters(k).size(); ++i)
      out.problem->AddParameterBlock(out.blocks[k + 1] + i, 1);
  if (freedom) out.camera_shift.assign(freedom->perturbations->size(), 0.0);
  const bool dense_row = AddSampleResiduals(options, samples, depths, freedom, split, out);
  for (std::size_t k = 0; freedom && k < out.camera_shift.size(); ++k)
    BoundParameter(*out.problem, out.camera_shift.data(), static_cast<int>(k), -freedom->bound_sigma,
                   freedom->bound_sigma);
  ConstrainEffects(definition, split, out);
  if (definition.form == model::BaseForm::kTangent && out.problem->HasParameterBlock(out.blocks[0]))
    out.problem->SetManifold(out.blocks[0], new TangentFormManifold);
  const bool any_split = std::find(split.begin(), split.end(), true) != split.end();
  const bool sparse_effect =
      std::any_of(m.Effects().begin(), m.Effects().end(), [](const auto& e) { return e->GivesSupport(); });
  ceres::Solver::Summary summary;
  const ceres::Solver::Options solver = SolverOptions(options, m.Flat().size(), sparse_effect, any_split, dense_row);
  if (freedom && !start) {
    // The model first, with the cameras held: from its initial values the
    // bounded shifts ran to their bounds before the base form came near, and
    // stayed (a wide-angle room, cameras from outlines: 31 iterations
    // without convergence, 11 raw where the fit without the cameras had 0.25).
    out.problem->SetParameterBlockConstant(out.camera_shift.data());
    ceres::Solve(solver, out.problem.get(), &summary);
    out.problem->SetParameterBlockVariable(out.camera_shift.data());
  }
  ceres::Solve(solver, out.problem.get(), &summary);
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.report = summary.BriefReport();
  const std::vector<double> flat = m.Flat();
  out.usable = summary.termination_type != ceres::FAILURE && std::isfinite(summary.final_cost) &&
               std::all_of(flat.begin(), flat.end(), [](double v) { return std::isfinite(v); });
  if (summary.termination_type == ceres::FAILURE && !summary.message.empty())
    out.report += " (" + summary.message + ")";
  return out;
}

// J^T J's pseudo-inverse without eigenvalues below 1e-14 of the largest, as
// Ceres' DENSE_SVD with null_space_rank -1 gives it.
Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& jtj) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(jtj);
  const Eigen::VectorXd lambda = eigen.eigenvalues();
  const double largest = lambda.size() ? lambda.maxCoeff() : 0;
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(lambda.size());
  for (Eigen::Index i = 0; i < lambda.size(); ++i)
    if (lambda[i] > 1e-14 * largest) inverse[i] = 1 / lambda[i];
  return eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
}

// The covariance of a large model's free parameters from its normal
// equations, as Ceres' DENSE_SVD with null_space_rank -1 gives it (the
// pseudo-inverse of J^T J without eigenvalues below 1e-14 of the largest),
// but with J^T J summed from each sample's gradient with its zeros skipped:
// DENSE_SVD decomposes the whole Jacobian, samples x parameters (Herrera's
// 146,862 samples x 356: 420 MB and most of a refit's time). Rows are
// weighted by the loss as Ceres' corrector does (sqrt of rho'; Huber's rho''
// is never positive). Returns the flat parameters' covariance, frozen rows 0.
std::vector<std::vector<double>> NormalEquationCovariance(const DepthFitOptions& options, const Solved& solved,
                                                          const std::vector<PairedSample>& samples,
                                                          const CameraFreedom* freedom) {
  const model::DepthModel& m = *solved.model;
  // Columns: every free parameter, then the camera weights (free with them).
  std::vector<int> block_size{static_cast<int>(m.Base().size())};
  for (std::size_t k = 0; k < m.Effects().size(); ++k)
    block_size.push_back(static_cast<int>(m.EffectParameters(k).size()));
  const std::size_t shifts = freedom ? freedom->perturbations->size() : 0;
  if (shifts) block_size.push_back(static_cast<int>(shifts));
  std::vector<int> column_of;  // per parameter of every block, -1 when frozen
  int columns = 0;
  for (std::size_t b = 0; b < block_size.size(); ++b) {
    const bool camera_weights = shifts > 0 && b + 1 == block_size.size();
    const bool free = b == 0 || camera_weights || IsFree(*solved.problem, solved.blocks[b]);
    for (int i = 0; i < block_size[b]; ++i) column_of.push_back(free ? columns++ : -1);
  }
  std::vector<const double*> values(solved.blocks.begin(), solved.blocks.end());
  if (shifts) values.push_back(solved.camera_shift.data());
  const std::unique_ptr<ceres::LossFunction> loss(options.huber_raw > 0 ? new ceres::HuberLoss(options.huber_raw)
                                                                        : nullptr);
  using Matrix = Eigen::MatrixXd;
  // Rows whose every entry may be non-zero (no effect gives its support) are
  // summed as one matrix product per range, not entry by entry (a 60-term
  // formula over Herrera's 151,321 samples: 0.4 s of each fit that way).
  const bool dense_rows =
      std::none_of(m.Effects().begin(), m.Effects().end(), [](const auto& e) { return e->GivesSupport(); });
  const auto accumulate = [&](const tbb::blocked_range<std::size_t>& range, Matrix jtj) {
    std::vector<double> gradient(column_of.size());
    std::vector<double*> jacobians;
    for (std::size_t b = 0, at = 0; b < block_size.size(); at += static_cast<std::size_t>(block_size[b++]))
      jacobians.push_back(&gradient[at]);
    std::vector<std::pair<int, double>> nonzero;
    Matrix rows = Matrix::Zero(dense_rows ? static_cast<Eigen::Index>(range.size()) : 0, columns);
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      const PairedSample& s = samples[i];
      std::vector<double> shift;
      for (std::size_t k = 0; k < shifts; ++k) shift.push_back((*freedom->perturbations)[k][i] - s.depth_m);
      const ComposedResidual residual(solved.model.get(), &s, s.depth_m, ReadingWeight(options, s), std::move(shift));
      double r = 0;
      if (!residual.Evaluate(values.data(), &r, jacobians.data())) continue;
      double weight = 1;
      if (loss) {
        double rho[3];
        loss->Evaluate(r * r, rho);
        weight = std::sqrt(std::max(0.0, rho[1]));
      }
      if (dense_rows) {
        const auto row = static_cast<Eigen::Index>(i - range.begin());
        for (std::size_t j = 0; j < gradient.size(); ++j)
          if (column_of[j] >= 0) rows(row, column_of[j]) = weight * gradient[j];
        continue;
      }
      nonzero.clear();
      for (std::size_t j = 0; j < gradient.size(); ++j)
        if (column_of[j] >= 0 && gradient[j] != 0) nonzero.emplace_back(column_of[j], weight * gradient[j]);
      for (const auto& [a, ga] : nonzero)
        for (const auto& [b, gb] : nonzero) jtj(a, b) += ga * gb;
    }
    if (dense_rows) jtj.noalias() += rows.transpose() * rows;
    return jtj;
  };
  Matrix jtj = tbb::parallel_reduce(tbb::blocked_range<std::size_t>(0, samples.size(), 2048),
                                    Matrix(Matrix::Zero(columns, columns)), accumulate,
                                    [](const Matrix& a, const Matrix& b) -> Matrix { return a + b; });
  // The effects' weak priors are rows of the Jacobian too: 1 / sigma each.
  for (std::size_t k = 0, at = block_size[0]; k < m.Effects().size(); at += static_cast<std::size_t>(block_size[++k])) {
    const auto& parameters = m.Effects()[k]->Parameters();
    for (std::size_t i = 0; i < parameters.size(); ++i) {
      const int c = column_of[at + i];
      if (c >= 0 && parameters[i].prior_sigma > 0)
        jtj(c, c) += 1 / (parameters[i].prior_sigma * parameters[i].prior_sigma);
    }
  }
  const Matrix pseudo_inverse = PseudoInverse(jtj);
  const std::size_t np = m.Flat().size();
  std::vector<std::vector<double>> out(np, std::vector<double>(np, 0.0));
  for (std::size_t i = 0; i < np; ++i)
    for (std::size_t j = 0; j < np; ++j)
      if (column_of[i] >= 0 && column_of[j] >= 0) out[i][j] = pseudo_inverse(column_of[i], column_of[j]);
  return out;
}

std::vector<const PairedSample*> Pointers(const std::vector<PairedSample>& samples) {
  std::vector<const PairedSample*> all;
  for (const auto& s : samples) all.push_back(&s);
  return all;
}

}  // namespace

model::Covariates CovariatesOf(const PairedSample& s) {
  return {s.raw,        s.u,          s.v,          s.x,          s.y,      s.time_s,  s.tilt_deg,
          s.gradient_u, s.gradient_v, s.velocity_u, s.velocity_v, s.albedo, s.raw_rate};
}

model::Covariates FitCovariatesOf(const PairedSample& s) {
  model::Covariates c = CovariatesOf(s);
  if (std::isfinite(s.fit_raw)) c.raw = s.fit_raw;
  return c;
}

std::size_t EvenStride(std::size_t count, std::size_t at_most) {
  return std::max<std::size_t>(1, (count + at_most - 1) / std::max<std::size_t>(1, at_most));
}

std::vector<int> FoldsByPose(const std::vector<PairedSample>& samples, int folds) {
  std::map<int, int> fold_of_pose;
  for (const auto& s : samples) fold_of_pose.emplace(s.pose, 0);
  int k = 0;
  for (auto& [pose, fold] : fold_of_pose) fold = folds > 0 ? k++ % folds : 0;
  std::vector<int> out;
  for (const auto& s : samples) out.push_back(fold_of_pose[s.pose]);
  return out;
}

ResidualStats Summarize(std::vector<double> r) {
  r.erase(std::remove_if(r.begin(), r.end(), [](double v) { return !std::isfinite(v); }), r.end());
  ResidualStats s;
  s.count = static_cast<int>(r.size());
  if (r.empty()) return s;
  const double n = static_cast<double>(r.size());
  s.mean = std::accumulate(r.begin(), r.end(), 0.0) / n;
  double sq = 0, dev = 0;
  for (double v : r) {
    sq += v * v;
    dev += (v - s.mean) * (v - s.mean);
    s.max_abs = std::max(s.max_abs, std::abs(v));
  }
  s.rms = std::sqrt(sq / n);
  s.sigma = r.size() > 1 ? std::sqrt(dev / (n - 1)) : 0;
  std::sort(r.begin(), r.end());
  const auto at = [&](double q) { return r[static_cast<std::size_t>(q * (n - 1))]; };
  s.p05 = at(0.05);
  s.p50 = at(0.5);
  s.p95 = at(0.95);
  return s;
}

WarmStart WarmStartFrom(const DepthFit& fit) {
  const model::DepthModel m = fit.Model();
  WarmStart start{fit.definition.form, m.Base(), {}};
  for (std::size_t k = 0; k < m.Effects().size(); ++k)
    if (!fit.definition.effects[k].frozen) start.effects[fit.definition.effects[k].name] = m.EffectParameters(k);
  return start;
}

namespace {
// The flat start of `definition` under `start`: blocks that match take its
// values, the others (and frozen effects) keep their initial ones.
std::vector<double> StartValues(const model::ModelDefinition& definition, const WarmStart& start) {
  model::DepthModel m(definition);
  if (start.form == definition.form && start.base.size() == m.Base().size()) m.Base() = start.base;
  for (std::size_t k = 0; k < m.Effects().size(); ++k) {
    const auto found = start.effects.find(definition.effects[k].name);
    if (definition.effects[k].frozen || found == start.effects.end()) continue;
    if (found->second.size() == m.EffectParameters(k).size()) m.EffectParameters(k) = found->second;
  }
  return m.Flat();
}
}  // namespace

model::DepthModel DepthFit::Model() const {
  model::DepthModel m(definition);
  m.SetFlat(parameters);
  return m;
}

namespace {
using Matrix = std::vector<std::vector<double>>;

// With effects, their raw covariate is the base form's prediction from a fit
// without them (see PairedSample::fit_raw); none: the samples stay as they are.
std::vector<PairedSample> WithFitRaw(const DepthFitOptions& options, const model::ModelDefinition& definition,
                                     const std::vector<PairedSample>& measured, FitSeconds& seconds) {
  if (definition.effects.empty()) return {};
  std::vector<PairedSample> with_fit_raw = measured;
  const StepClock clock;
  const Solved base = Solve(options, {definition.form, {}}, Pointers(measured));
  for (auto& s : with_fit_raw) s.fit_raw = model::RawFromDepth(definition.form, base.model->Base().data(), s.depth_m);
  seconds.pre_fit = clock.Seconds();
  return with_fit_raw;
}

// An effect's offset at p: from its terms when it is linear in its
// parameters (a formula's are computed once here and reused by the fit,
// instead of one run of the whole formula per sample first).
double OffsetAtStart(const model::Effect& effect, const std::vector<double>& p, const model::Covariates& c) {
  const double* terms = effect.LinearTerms(c);
  return terms ? model::LinearOffset(terms, p.data(), p.size()) : effect.RawOffset(p.data(), c);
}

// A formula that divides by zero (or an effect outside its domain) would
// stall the solver without a word: name the sample instead.
std::optional<Rejection> NotFiniteAtStart(const model::ModelDefinition& definition,
                                          const std::vector<PairedSample>& samples) {
  const model::DepthModel initial(definition);
  for (const auto& s : samples) {
    const model::Covariates c = FitCovariatesOf(s);
    for (std::size_t k = 0; k < initial.Effects().size(); ++k) {
      if (std::isfinite(OffsetAtStart(*initial.Effects()[k], initial.EffectParameters(k), c))) continue;
      return Rejection{"fit", "effect " + initial.Effects()[k]->Name() +
                                  " is not finite at its initial parameters for the sample of frame " +
                                  std::to_string(s.frame) + " at pixel (" + std::to_string(s.u) + ", " +
                                  std::to_string(s.v) + "), raw " + std::to_string(s.raw) + " (a division by zero?)"};
    }
  }
  return std::nullopt;
}

// A sample's true depth, with the cameras where the fit moved them.
double TrueDepth(const Solved& fitted, const std::vector<PairedSample>& samples,
                 const DepthPerturbations& perturbations, std::size_t i) {
  double depth = samples[i].depth_m;
  for (std::size_t k = 0; k < fitted.camera_shift.size(); ++k)
    depth += fitted.camera_shift[k] * (perturbations[k][i] - samples[i].depth_m);
  return depth;
}

// Covariance of the free parameters, scaled by the residual variance (Ceres
// assumes unit-variance residuals); frozen blocks have none. Large models,
// or large Jacobians, take it from their normal equations; small ones from
// Ceres' dense SVD, which decomposes the whole Jacobian (a 60-term formula
// over Herrera's 151,321 samples: 4.0 s of a 9.7 s fit).
Matrix IndependentCovariance(const DepthFitOptions& options, const Solved& solved,
                             const std::vector<PairedSample>& samples, const CameraFreedom* free_cameras,
                             double variance) {
  constexpr std::size_t kDenseSvdEntries = 2'000'000;  // 16 MB of Jacobian
  const std::size_t np = solved.model->Flat().size();
  Matrix independent(np, std::vector<double>(np, 0.0));
  if (np >= options.sparse_from_parameters || samples.size() * np > kDenseSvdEntries) {
    independent = NormalEquationCovariance(options, solved, samples, free_cameras);
    for (auto& row : independent)
      for (double& v : row) v *= variance;
    return independent;
  }
  std::vector<double*> free_blocks;
  std::vector<std::size_t> block_offset;
  std::size_t offset = 0;
  for (double* block : solved.blocks) {
    if (IsFree(*solved.problem, block)) free_blocks.push_back(block), block_offset.push_back(offset);
    offset += static_cast<std::size_t>(solved.problem->ParameterBlockSize(block));
  }
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.null_space_rank = -1;  // effects with no support in the data stay finite
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> pairs;
  for (double* a : free_blocks)
    for (double* b : free_blocks) pairs.emplace_back(a, b);
  if (!covariance.Compute(pairs, solved.problem.get())) return independent;
  for (std::size_t i = 0; i < free_blocks.size(); ++i) {
    for (std::size_t j = 0; j < free_blocks.size(); ++j) {
      const int ni = solved.problem->ParameterBlockSize(free_blocks[i]);
      const int nj = solved.problem->ParameterBlockSize(free_blocks[j]);
      std::vector<double> block(static_cast<std::size_t>(ni * nj));
      covariance.GetCovarianceBlock(free_blocks[i], free_blocks[j], block.data());
      for (int a = 0; a < ni; ++a)
        for (int b = 0; b < nj; ++b)
          independent[block_offset[i] + a][block_offset[j] + b] =
              block[static_cast<std::size_t>(a * nj + b)] * variance;
    }
  }
  return independent;
}

// The cameras' part of the covariance: the fit redone with the true depths of
// each camera perturbation (side by side, combined in order), and each one's
// raw RMS change into fit.camera_raw_rms. With the cameras free the
// perturbations were parameters instead, and are not refitted.
StageResult<Matrix> CameraCovariance(const DepthFitOptions& options, const model::ModelDefinition& definition,
                                     const std::vector<PairedSample>& samples, const DepthPerturbations& refitted,
                                     DepthFit& fit, FitSeconds& seconds) {
  const std::size_t np = fit.parameters.size();
  const std::size_t stride = EvenStride(samples.size(), options.max_refit_samples);
  std::vector<const PairedSample*> thinned;
  std::vector<std::size_t> thinned_index;
  for (std::size_t i = 0; i < samples.size(); i += stride) thinned.push_back(&samples[i]), thinned_index.push_back(i);
  std::vector<std::vector<double>> moved_depths(refitted.size());
  std::vector<Solved> moved_fits(refitted.size());
  seconds.camera_refits.assign(refitted.size(), 0.0);
  const StepClock refits_clock;
  {
    std::optional<StepProgress> progress;
    if (!options.progress.empty())
      progress.emplace(options.progress + ": camera refit", static_cast<int>(refitted.size()));
    tbb::parallel_for(std::size_t{0}, refitted.size(), [&](std::size_t k) {
      const StepClock clock;
      for (std::size_t i : thinned_index) moved_depths[k].push_back(refitted[k][i]);
      moved_fits[k] = Solve(options, definition, thinned, &moved_depths[k], &fit.parameters);
      seconds.camera_refits[k] = clock.Seconds();
      if (progress) progress->Done();
    });
  }
  seconds.camera_refits_wall = refits_clock.Seconds();
  const model::DepthModel m = fit.Model();
  Matrix cameras(np, std::vector<double>(np, 0.0));
  for (std::size_t k = 0; k < refitted.size(); ++k) {
    const Solved& moved = moved_fits[k];
    if (!moved.usable)
      return Rejection{"fit", "the refit with camera perturbation " + std::to_string(k) + " failed: " + moved.report};
    double change = 0;
    for (std::size_t j = 0; j < thinned.size(); ++j) {
      const model::Covariates c = FitCovariatesOf(*thinned[j]);
      change += std::pow(moved.model->PredictRaw(moved_depths[k][j], c) - m.PredictRaw(thinned[j]->depth_m, c), 2);
    }
    if (k < options.perturbations_in_floor)
      fit.camera_raw_rms.push_back(thinned.empty() ? 0.0 : std::sqrt(change / static_cast<double>(thinned.size())));
    const std::vector<double> p = moved.model->Flat();
    for (std::size_t i = 0; i < np; ++i)
      for (std::size_t j = 0; j < np; ++j) cameras[i][j] += (p[i] - fit.parameters[i]) * (p[j] - fit.parameters[j]);
  }
  return cameras;
}

// Cross-validation by pose: each fold's poses predicted by a fit to the
// others, into fit.held_out_residual_raw and held_out_mm. Returns each usable
// fold's parameters (for the jackknife).
std::vector<std::vector<double>> HoldOutPoses(const DepthFitOptions& options, const model::ModelDefinition& definition,
                                              const std::vector<PairedSample>& samples,
                                              const DepthPerturbations& perturbations,
                                              const CameraFreedom* free_cameras, DepthFit& fit, FitSeconds& seconds) {
  const std::size_t np = fit.parameters.size();
  const std::size_t stride = EvenStride(samples.size(), options.max_refit_samples);
  const std::vector<int> fold = FoldsByPose(samples, options.folds);
  const int folds = std::min<int>(options.folds, fold.empty() ? 0 : *std::max_element(fold.begin(), fold.end()) + 1);
  fit.held_out_residual_raw.assign(samples.size(), std::numeric_limits<double>::quiet_NaN());
  std::vector<std::vector<std::size_t>> tests(folds >= 2 ? folds : 0);
  std::vector<std::optional<Solved>> fold_fits(tests.size());
  seconds.folds.assign(tests.size(), 0.0);
  const StepClock folds_clock;
  std::optional<StepProgress> fold_progress;
  if (!options.progress.empty()) fold_progress.emplace(options.progress + ": fold", static_cast<int>(tests.size()));
  tbb::parallel_for(std::size_t{0}, tests.size(), [&](std::size_t f) {
    const StepClock clock;
    std::vector<const PairedSample*> train;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      if (fold[i] == static_cast<int>(f))
        tests[f].push_back(i);
      else if (i % stride == 0)
        train.push_back(&samples[i]);
    }
    if (train.size() < 3 * np || tests[f].empty()) return;
    // From the model's initial values, never from a fit that saw the held-out
    // pose: a pattern's controls that only that pose reaches would keep the
    // values it gave them, and its error would look predicted (a candidate
    // started warm beat the model it extends on 29 of 30 poses that way).
    fold_fits[f] = Solve(options, definition, train, nullptr, nullptr, free_cameras);
    seconds.folds[f] = clock.Seconds();
    if (fold_progress) fold_progress->Done();
  });
  fold_progress.reset();
  seconds.folds_wall = folds_clock.Seconds();
  std::vector<std::vector<double>> fold_parameters;
  std::vector<double> held_mm;
  for (std::size_t f = 0; f < tests.size(); ++f) {
    if (!fold_fits[f] || !fold_fits[f]->usable) continue;
    const Solved& cv = *fold_fits[f];
    fold_parameters.push_back(cv.model->Flat());
    for (std::size_t i : tests[f]) {
      const double truth = TrueDepth(cv, samples, perturbations, i);
      fit.held_out_residual_raw[i] = samples[i].raw - cv.model->PredictRaw(truth, FitCovariatesOf(samples[i]));
      held_mm.push_back(1000 * (cv.model->Depth(CovariatesOf(samples[i])) - truth));
    }
  }
  fit.held_out_raw = Summarize(fit.held_out_residual_raw);
  fit.held_out_mm = Summarize(held_mm);
  return fold_parameters;
}

// Grouped jackknife over the folds: (K-1)/K sum (p_k - mean)^2. Where most
// free parameters vary more over pose folds than the independent-sample
// covariance says, poses share errors and the jackknife is the honest one.
Matrix SamplesCovariance(const Matrix& independent, const std::vector<std::vector<double>>& fold_parameters) {
  if (fold_parameters.size() < 3) return independent;
  const std::size_t np = independent.size();
  const double k = static_cast<double>(fold_parameters.size());
  std::vector<double> mean(np, 0.0);
  for (const auto& p : fold_parameters)
    for (std::size_t i = 0; i < np; ++i) mean[i] += p[i] / k;
  Matrix jackknife(np, std::vector<double>(np, 0.0));
  for (const auto& p : fold_parameters)
    for (std::size_t i = 0; i < np; ++i)
      for (std::size_t j = 0; j < np; ++j) jackknife[i][j] += (k - 1) / k * (p[i] - mean[i]) * (p[j] - mean[j]);
  int free = 0, larger = 0;
  for (std::size_t i = 0; i < np; ++i) {
    if (jackknife[i][i] == 0 && independent[i][i] == 0) continue;  // frozen
    ++free;
    larger += jackknife[i][i] > independent[i][i];
  }
  return 2 * larger > free ? jackknife : independent;
}

// fit.covariance and its sigmas: the samples' part plus the cameras'. Frozen
// parameters have none (not even the jackknife's rounding).
void SetCovariance(const Matrix& samples_part, const Matrix& cameras, DepthFit& fit) {
  const model::DepthModel m = fit.Model();
  std::vector<bool> frozen(m.Base().size(), false);
  for (std::size_t k = 0; k < m.Effects().size(); ++k)
    frozen.insert(frozen.end(), m.EffectParameters(k).size(), fit.definition.effects[k].frozen);
  const std::size_t np = frozen.size();
  fit.covariance.assign(np, std::vector<double>(np));
  for (std::size_t i = 0; i < np; ++i) {
    for (std::size_t j = 0; j < np; ++j)
      fit.covariance[i][j] = frozen[i] || frozen[j] ? 0.0 : samples_part[i][j] + cameras[i][j];
    fit.sigma.push_back(std::sqrt(std::max(0.0, fit.covariance[i][i])));
    fit.sigma_samples.push_back(frozen[i] ? 0.0 : std::sqrt(std::max(0.0, samples_part[i][i])));
    fit.sigma_cameras.push_back(frozen[i] ? 0.0 : std::sqrt(cameras[i][i]));
  }
}

// The fitted model's residuals on the samples it was fitted to.
void SetResiduals(const Solved& solved, const std::vector<PairedSample>& samples,
                  const DepthPerturbations& perturbations, DepthFit& fit) {
  const model::DepthModel& m = *solved.model;
  std::vector<double> mm_residuals;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const PairedSample& s = samples[i];
    const double truth = TrueDepth(solved, samples, perturbations, i);
    fit.residual_raw.push_back(s.raw - m.PredictRaw(truth, FitCovariatesOf(s)));
    mm_residuals.push_back(1000 * (m.Depth(CovariatesOf(s)) - truth));
  }
  fit.raw = Summarize(fit.residual_raw);
  fit.depth_mm = Summarize(mm_residuals);
}

// The sum of the weighted residuals' squares (ReadingWeight): Ceres' cost,
// twice, without the loss.
double WeightedSquares(const DepthFitOptions& options, const std::vector<PairedSample>& samples,
                       const std::vector<double>& residuals) {
  double sum = 0;
  for (std::size_t i = 0; i < samples.size(); ++i)
    sum += std::pow(ReadingWeight(options, samples[i]) * residuals[i], 2);
  return sum;
}

// Without a held-out error the fit cannot be judged, and an RMS of 0 would
// read as perfect; non-finite residuals cannot be judged either.
std::optional<Rejection> Unjudgeable(const DepthFit& fit, const std::vector<PairedSample>& samples) {
  if (fit.held_out_raw.count == 0) {
    std::set<int> poses;
    for (const auto& s : samples) poses.insert(s.pose);
    // A fold is fitted to the other poses' samples, 3 per parameter at least
    // (HoldOutPoses): a large model on a small session fails there, not for
    // want of poses (the words said "needs at least 2 board poses" of a
    // 770-parameter pattern over 15).
    const std::size_t np = fit.parameters.size();
    if (poses.size() < 2)
      return Rejection{"fit",
                       "no held-out error: cross-validation by pose needs at least 2 board poses; the samples "
                       "come from " +
                           std::to_string(poses.size())};
    return Rejection{"fit", "no held-out error: with a pose held out, the other poses' samples are too few for " +
                                std::to_string(np) + " parameters (" + std::to_string(3 * np) + " needed; " +
                                std::to_string(samples.size()) + " samples from " + std::to_string(poses.size()) +
                                " poses in all)"};
  }
  if (!std::isfinite(fit.raw.rms) || !std::isfinite(fit.held_out_raw.rms))
    return Rejection{"fit", "the residuals are not finite (raw RMS " + std::to_string(fit.raw.rms) + ")"};
  return std::nullopt;
}

// Why these samples (with their fit raw) cannot be fitted with this model, if they cannot.
std::optional<Rejection> Unfittable(const model::ModelDefinition& definition,
                                    const std::vector<PairedSample>& samples) {
  if (auto rejection = NotFiniteAtStart(definition, samples)) return rejection;
  const std::size_t np = model::DepthModel(definition).Flat().size();
  if (samples.size() >= 3 * np) return std::nullopt;
  return Rejection{"fit", "too few paired samples (" + std::to_string(samples.size()) + ") for " + std::to_string(np) +
                              " parameters"};
}
}  // namespace

namespace {
// The fit of every sample, its residuals, covariance and camera refits
// (everything but the folds) into fit; a rejection when it cannot be used.
std::optional<Rejection> FitAllSamples(const DepthFitOptions& options, const model::ModelDefinition& definition,
                                       const std::vector<PairedSample>& samples,
                                       const DepthPerturbations& perturbations, const CameraFreedom* free_cameras,
                                       DepthFit& fit, Matrix& independent, Matrix& cameras, FitSeconds& seconds) {
  const std::size_t np = model::DepthModel(definition).Flat().size();
  const StepClock fit_clock;
  const std::optional<std::vector<double>> start =
      options.start ? std::optional(StartValues(definition, *options.start)) : std::nullopt;
  Solved solved = Solve(options, definition, Pointers(samples), nullptr, start ? &*start : nullptr, free_cameras);
  seconds.fit = fit_clock.Seconds();
  if (!solved.usable) return Rejection{"fit", "the solver failed: " + solved.report};
  fit.definition = definition;
  fit.parameters = solved.model->Flat();
  fit.names = solved.model->FlatNames();
  fit.converged = solved.converged;
  fit.solver_report = solved.report;
  fit.camera_shift_sigma = solved.camera_shift;
  SetResiduals(solved, samples, perturbations, fit);
  const StepClock covariance_clock;
  const double variance =
      WeightedSquares(options, samples, fit.residual_raw) / std::max<double>(1, samples.size() - np);
  independent = IndependentCovariance(options, solved, samples, free_cameras, variance);
  seconds.covariance = covariance_clock.Seconds();
  static const DepthPerturbations kNone;
  StageResult<Matrix> moved =
      CameraCovariance(options, definition, samples, free_cameras ? kNone : perturbations, fit, seconds);
  if (const auto* rejection = std::get_if<Rejection>(&moved)) return *rejection;
  cameras = std::move(std::get<Matrix>(moved));
  return std::nullopt;
}
}  // namespace

StageResult<DepthFit> RunDepthModelFit(const DepthFitOptions& options, const model::ModelDefinition& definition,
                                       const std::vector<PairedSample>& measured,
                                       const DepthPerturbations& perturbations) {
  const StepClock total_clock;
  FitSeconds seconds;
  const std::vector<PairedSample> with_fit_raw = WithFitRaw(options, definition, measured, seconds);
  const std::vector<PairedSample>& samples = with_fit_raw.empty() ? measured : with_fit_raw;
  if (auto rejection = Unfittable(definition, samples)) return *rejection;
  const CameraFreedom freedom{&perturbations, samples.data(), options.camera_freedom_sigma};
  const CameraFreedom* free_cameras = options.camera_freedom_sigma > 0 && !perturbations.empty() ? &freedom : nullptr;
  // The folds start from the model's initial values, not from the fit of
  // every sample (HoldOutPoses): side by side with it, they use the core
  // its solve leaves idle (Herrera's 60-term formula: 1.2 s of each fit).
  DepthFit fit, folds;
  folds.parameters = model::DepthModel(definition).Flat();
  Matrix independent, cameras;
  std::optional<Rejection> rejection;
  std::vector<std::vector<double>> fold_parameters;
  tbb::parallel_invoke(
      [&] {
        rejection = FitAllSamples(options, definition, samples, perturbations, free_cameras, fit, independent, cameras,
                                  seconds);
      },
      [&] {
        fold_parameters = HoldOutPoses(options, definition, samples, perturbations, free_cameras, folds, seconds);
      });
  if (rejection) return *rejection;
  fit.held_out_residual_raw = std::move(folds.held_out_residual_raw);
  fit.held_out_raw = folds.held_out_raw;
  fit.held_out_mm = folds.held_out_mm;
  if (auto unjudgeable = Unjudgeable(fit, samples)) return *unjudgeable;
  SetCovariance(SamplesCovariance(independent, fold_parameters), cameras, fit);
  seconds.total = total_clock.Seconds();
  fit.seconds = std::move(seconds);
  return fit;
}

StageResult<HeldOutFit> RunHeldOutFit(const DepthFitOptions& options, const model::ModelDefinition& definition,
                                      const std::vector<PairedSample>& measured) {
  FitSeconds seconds;
  const std::vector<PairedSample> with_fit_raw = WithFitRaw(options, definition, measured, seconds);
  const std::vector<PairedSample>& samples = with_fit_raw.empty() ? measured : with_fit_raw;
  if (auto rejection = Unfittable(definition, samples)) return *rejection;
  DepthFit folds;  // only its held-out fields are filled
  folds.parameters = model::DepthModel(definition).Flat();
  HoldOutPoses(options, definition, samples, {}, nullptr, folds, seconds);
  if (auto rejection = Unjudgeable(folds, samples)) return *rejection;
  return HeldOutFit{std::move(folds.held_out_residual_raw), folds.held_out_raw, folds.parameters.size()};
}

}  // namespace speckle
