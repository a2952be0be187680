#include "stages/depth_model_fit.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <map>
#include <numeric>

namespace speckle {
namespace {

// Up to three parameters in one block: the base forms have two or three.
template <int N>
struct RawResidual {
  RawResidual(model::BaseForm form, double raw, double depth_m) : form(form), raw(raw), depth_m(depth_m) {}
  template <typename T>
  bool operator()(const T* p, T* residual) const {
    residual[0] = T(raw) - model::RawFromDepth(form, p, T(depth_m));
    return true;
  }
  model::BaseForm form;
  double raw, depth_m;
};

template <int N>
ceres::CostFunction* MakeCost(model::BaseForm form, const PairedSample& s) {
  return new ceres::AutoDiffCostFunction<RawResidual<N>, 1, N>(new RawResidual<N>(form, s.raw, s.depth_m));
}

struct Solved {
  std::vector<double> p;
  bool converged = false;
  std::string report;
  std::unique_ptr<ceres::Problem> problem;
};

Solved Solve(const DepthFitOptions& options, const std::vector<const PairedSample*>& samples) {
  Solved out;
  out.p = model::Info(options.form).initial;
  out.problem = std::make_unique<ceres::Problem>();
  const int n = static_cast<int>(out.p.size());
  for (const PairedSample* s : samples) {
    ceres::CostFunction* cost = n == 2 ? MakeCost<2>(options.form, *s) : MakeCost<3>(options.form, *s);
    out.problem->AddResidualBlock(cost, options.huber_raw > 0 ? new ceres::HuberLoss(options.huber_raw) : nullptr,
                                  out.p.data());
  }
  ceres::Solver::Options solver;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = 1e-12;
  solver.parameter_tolerance = 1e-12;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, out.problem.get(), &summary);
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.report = summary.BriefReport();
  return out;
}

double ModelRaw(model::BaseForm form, const std::vector<double>& p, double depth_m) {
  return model::RawFromDepth(form, p.data(), depth_m);
}
double ModelDepthMm(model::BaseForm form, const std::vector<double>& p, double raw) {
  return 1000 * model::DepthFromRaw(form, p.data(), raw);
}

}  // namespace

ResidualStats Summarize(std::vector<double> r) {
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

StageResult<DepthFit> RunDepthModelFit(const DepthFitOptions& options, const std::vector<PairedSample>& samples,
                                       const DepthPerturbations& perturbations) {
  const int n_params = static_cast<int>(model::Info(options.form).parameters.size());
  if (static_cast<int>(samples.size()) < 3 * n_params) {
    return Rejection{"fit", "too few paired samples to fit (" + std::to_string(samples.size()) + ")"};
  }
  std::vector<const PairedSample*> all;
  for (const auto& s : samples) all.push_back(&s);
  Solved solved = Solve(options, all);
  DepthFit fit;
  fit.form = options.form;
  fit.parameters = solved.p;
  fit.converged = solved.converged;
  fit.solver_report = solved.report;
  std::vector<double> raw_residuals, mm_residuals;
  for (const auto& s : samples) {
    raw_residuals.push_back(s.raw - ModelRaw(options.form, fit.parameters, s.depth_m));
    mm_residuals.push_back(ModelDepthMm(options.form, fit.parameters, s.raw) - 1000 * s.depth_m);
  }
  fit.residual_raw = raw_residuals;
  fit.raw = Summarize(raw_residuals);
  fit.depth_mm = Summarize(mm_residuals);

  // Covariance, scaled by the residual variance (Ceres assumes unit-variance residuals).
  ceres::Covariance::Options covariance_options;
  ceres::Covariance covariance(covariance_options);
  std::vector<double> block(static_cast<std::size_t>(n_params * n_params), 0.0);
  double* block_pointer = solved.p.data();  // the block registered with the problem
  const std::vector<std::pair<const double*, const double*>> blocks = {{block_pointer, block_pointer}};
  if (covariance.Compute(blocks, solved.problem.get())) {
    covariance.GetCovarianceBlock(block_pointer, block_pointer, block.data());
  }
  const double variance = fit.raw.rms * fit.raw.rms * samples.size() / std::max<double>(1, samples.size() - n_params);
  const std::size_t np = static_cast<std::size_t>(n_params);
  std::vector<std::vector<double>> cameras(np, std::vector<double>(np, 0.0));
  for (const auto& depths : perturbations) {
    std::vector<PairedSample> moved_samples = samples;
    for (std::size_t k = 0; k < samples.size(); ++k) moved_samples[k].depth_m = depths.at(k);
    std::vector<const PairedSample*> pointers;
    for (const auto& s : moved_samples) pointers.push_back(&s);
    const Solved moved = Solve(options, pointers);
    for (std::size_t i = 0; i < np; ++i)
      for (std::size_t j = 0; j < np; ++j)
        cameras[i][j] += (moved.p[i] - fit.parameters[i]) * (moved.p[j] - fit.parameters[j]);
  }
  fit.covariance.assign(np, std::vector<double>(np));
  std::vector<std::vector<double>> independent(np, std::vector<double>(np));
  for (std::size_t i = 0; i < np; ++i) {
    for (std::size_t j = 0; j < np; ++j) {
      independent[i][j] = block[i * np + j] * variance;
      fit.covariance[i][j] = independent[i][j] + cameras[i][j];
    }
    fit.sigma.push_back(std::sqrt(std::max(0.0, fit.covariance[i][i])));
    fit.sigma_samples.push_back(std::sqrt(std::max(0.0, block[i * np + i] * variance)));
    fit.sigma_cameras.push_back(std::sqrt(cameras[i][i]));
  }

  // Cross-validation by pose.
  std::map<int, int> fold_of_pose;
  for (const auto& s : samples) fold_of_pose.emplace(s.pose, 0);
  int k = 0;
  for (auto& [pose, fold] : fold_of_pose) fold = options.folds > 0 ? k++ % options.folds : 0;
  const int folds = std::min<int>(options.folds, static_cast<int>(fold_of_pose.size()));
  std::vector<double> held_raw, held_mm;
  std::vector<std::vector<double>> fold_parameters;
  for (int f = 0; f < folds && folds >= 2; ++f) {
    std::vector<const PairedSample*> train, test;
    for (const auto& s : samples) (fold_of_pose[s.pose] == f ? test : train).push_back(&s);
    if (train.size() < static_cast<std::size_t>(3 * n_params) || test.empty()) continue;
    const Solved cv = Solve(options, train);
    fold_parameters.push_back(cv.p);
    for (const PairedSample* s : test) {
      held_raw.push_back(s->raw - ModelRaw(options.form, cv.p, s->depth_m));
      held_mm.push_back(ModelDepthMm(options.form, cv.p, s->raw) - 1000 * s->depth_m);
    }
  }
  fit.held_out_raw = Summarize(held_raw);
  fit.held_out_mm = Summarize(held_mm);

  // Grouped jackknife over the folds: (K-1)/K sum (p_k - mean)^2. Where it
  // exceeds the independent-sample covariance, poses share errors and it is
  // the honest one.
  if (fold_parameters.size() >= 3) {
    const double k = static_cast<double>(fold_parameters.size());
    std::vector<double> mean(np, 0.0);
    for (const auto& p : fold_parameters)
      for (std::size_t i = 0; i < np; ++i) mean[i] += p[i] / k;
    std::vector<std::vector<double>> jackknife(np, std::vector<double>(np, 0.0));
    for (const auto& p : fold_parameters)
      for (std::size_t i = 0; i < np; ++i)
        for (std::size_t j = 0; j < np; ++j) jackknife[i][j] += (k - 1) / k * (p[i] - mean[i]) * (p[j] - mean[j]);
    bool larger = true;
    for (std::size_t i = 0; i < np; ++i) larger = larger && jackknife[i][i] > independent[i][i];
    if (larger) {
      for (std::size_t i = 0; i < np; ++i) {
        for (std::size_t j = 0; j < np; ++j) fit.covariance[i][j] += jackknife[i][j] - independent[i][j];
        fit.sigma[i] = std::sqrt(std::max(0.0, fit.covariance[i][i]));
        fit.sigma_samples[i] = std::sqrt(jackknife[i][i]);
      }
    }
  }
  return fit;
}

}  // namespace speckle
