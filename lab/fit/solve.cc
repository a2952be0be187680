#include "lab/fit/solve.h"

#include <algorithm>
#include <cmath>

#include "lab/fit/residual_blocks.h"
#include "lab/fit/tangent_form_manifold.h"
#include "stages/ceres_blocks.h"

namespace speckle::fitting {
namespace {

// sparse_effect: some effect gives its samples' support (effect.h), so its
// Jacobian is mostly zeros; any_split: some effect has a block per
// parameter; dense_row: some sample reaches all of them.
ceres::Solver::Options SolverOptions(const DepthFitOptions& options, std::size_t parameters, bool sparse_effect,
                                     bool any_split, bool dense_row) {
  ceres::Solver::Options solver;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = 1e-10;
  solver.parameter_tolerance = 1e-12;
  // Which linear solver, by the model's size and sparsity:
  // - A small model (a base form and a few effects) solves fastest dense.
  // - A B-spline field's samples each reach 16 of its hundreds of controls.
  //   Dense, J^T J costs samples x parameters^2 per iteration; with each
  //   control its own block and each sample holding only those it reaches,
  //   the sparsity is known before the solve and a sparse Cholesky costs
  //   samples x 18^2.
  // - A large effect that gives no support keeps one block, whose zeros
  //   Ceres' dynamic sparsity drops at each evaluation (slower: it writes and
  //   checks every column of every row).
  // - A large model without such an effect (a 60-term formula) is dense, and
  //   solves fastest dense.
  // The line search: with bounds on any parameter, Ceres follows every
  // trust-region step with a projected Armijo search that evaluates cost and
  // gradient again. The step is projected onto the bounds anyway, and Ceres
  // calls that search "not terribly effective" (its issue 187), so a dense
  // model's trust region alone decides. The large fields keep it: without it
  // a pattern's split and one-block fits end sigmas apart in its flat valley
  // (DepthFit.SplitBlocksMatchOneBlockPerEffect). The timings behind these
  // choices are in bench/results/speed.md.
  if (parameters >= options.sparse_from_parameters && sparse_effect) {
    solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    solver.dynamic_sparsity = !any_split;
    // Dogleg reaches the same optimum in fewer iterations here.
    solver.trust_region_strategy_type = ceres::DOGLEG;
    // A sample that reaches every control (a B-spline's last span, whose
    // control is minus the sum of the others) costs J^T J parameters^2
    // product terms, and a few hundred such samples dominate the solve.
    // Conjugate gradients on the normal equations never form J^T J.
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

}  // namespace

Solved Solve(const DepthFitOptions& options, const model::ModelDefinition& definition,
             const std::vector<const PairedSample*>& samples, const std::vector<double>* depths,
             const std::vector<double>* start, const CameraFreedom* freedom) {
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

double TrueDepth(const Solved& fitted, const std::vector<PairedSample>& samples,
                 const DepthPerturbations& perturbations, std::size_t i) {
  double depth = samples[i].depth_m;
  for (std::size_t k = 0; k < fitted.camera_shift.size(); ++k)
    depth += fitted.camera_shift[k] * (perturbations.depths[k][i] - samples[i].depth_m);
  return depth;
}

}  // namespace speckle::fitting
