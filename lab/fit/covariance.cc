#include "lab/fit/covariance.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>  // parallel_deterministic_reduce
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>

#include "lab/fit/composed_residual.h"
#include "stages/ceres_blocks.h"
#include "stages/step_clock.h"

namespace speckle::fitting {
namespace {

// J^T J's pseudo-inverse, each column scaled to a unit diagonal first
// (Jacobi), so that a direction is dropped for being undetermined, not for its
// units: unscaled (as Ceres' DENSE_SVD with null_space_rank -1 takes it), a
// reciprocal form's a, in 1/(m raw), made the largest eigenvalue 3e14 and
// dropped every spline control only its prior holds (0.04), whose sigma then
// read 0. Scaled, the largest is at most the column count, and what is
// dropped (below 1e-12 of it) the data does not determine. `unidentified`
// (per column) marks the columns that lean on a dropped direction: they
// cannot be told from zero or from each other.
Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& jtj, std::vector<bool>* unidentified) {
  const Eigen::Index n = jtj.rows();
  Eigen::VectorXd scale(n);
  for (Eigen::Index i = 0; i < n; ++i) scale[i] = jtj(i, i) > 0 ? 1 / std::sqrt(jtj(i, i)) : 0;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scale.asDiagonal() * jtj * scale.asDiagonal());
  const Eigen::VectorXd lambda = eigen.eigenvalues();
  const double largest = n ? lambda.maxCoeff() : 0;
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(n);
  unidentified->assign(static_cast<std::size_t>(n), false);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (lambda[i] > 1e-12 * largest) {
      inverse[i] = 1 / lambda[i];
      continue;
    }
    for (Eigen::Index c = 0; c < n; ++c)
      if (std::abs(eigen.eigenvectors()(c, i)) > 0.1) (*unidentified)[static_cast<std::size_t>(c)] = true;
  }
  return scale.asDiagonal() * eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose() *
         scale.asDiagonal();
}

// J^T J over the free columns, summed from each sample's gradient with its
// zeros skipped: Ceres' DENSE_SVD decomposes the whole Jacobian, samples x
// parameters (Herrera's 146,862 samples x 356: 420 MB and most of a refit's
// time). Rows are weighted by the loss as Ceres' corrector does (sqrt of
// rho'; Huber's rho'' is never positive).
struct Information {
  Eigen::MatrixXd jtj;
  std::vector<int> column_of;  // per flat parameter (camera weights after them), -1 when frozen
};

Information InformationMatrix(const DepthFitOptions& options, const Solved& solved,
                              const std::vector<PairedSample>& samples, const CameraFreedom* freedom) {
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
      for (std::size_t k = 0; k < shifts; ++k) shift.push_back(freedom->perturbations->depths[k][i] - s.depth_m);
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
  // Deterministic: the same chunks summed in the same order whatever the threads do. A work-stealing
  // reduce moved the last digits from run to run, and the joint calibration's sigmas, taken through the
  // largest directions of the cameras' covariance, grew that to 0.13 % (a fleet unit's first run).
  Matrix jtj = tbb::parallel_deterministic_reduce(tbb::blocked_range<std::size_t>(0, samples.size(), 2048),
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
  return {std::move(jtj), std::move(column_of)};
}

// Which flat parameters lean on a direction the information leaves
// undetermined.
std::vector<bool> FlatUnidentified(const Information& info, const std::vector<bool>& by_column, std::size_t np) {
  std::vector<bool> out(np, false);
  for (std::size_t i = 0; i < np; ++i)
    out[i] = info.column_of[i] >= 0 && by_column[static_cast<std::size_t>(info.column_of[i])];
  return out;
}

// Returns the flat parameters' covariance, frozen rows 0.
Matrix NormalEquationCovariance(const Information& info, std::size_t np, std::vector<bool>* unidentified) {
  std::vector<bool> by_column;
  const Eigen::MatrixXd pseudo_inverse = PseudoInverse(info.jtj, &by_column);
  *unidentified = FlatUnidentified(info, by_column, np);
  Matrix out(np, std::vector<double>(np, 0.0));
  for (std::size_t i = 0; i < np; ++i)
    for (std::size_t j = 0; j < np; ++j)
      if (info.column_of[i] >= 0 && info.column_of[j] >= 0)
        out[i][j] = pseudo_inverse(info.column_of[i], info.column_of[j]);
  return out;
}

}  // namespace

Matrix IndependentCovariance(const DepthFitOptions& options, const Solved& solved,
                             const std::vector<PairedSample>& samples, const CameraFreedom* free_cameras,
                             double variance, std::vector<bool>* unidentified) {
  const std::size_t np = solved.model->Flat().size();
  Matrix independent =
      NormalEquationCovariance(InformationMatrix(options, solved, samples, free_cameras), np, unidentified);
  for (auto& row : independent)
    for (double& v : row) v *= variance;
  return independent;
}

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
      for (std::size_t i : thinned_index) moved_depths[k].push_back(refitted.depths[k][i]);
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
    if (k < refitted.in_floor)
      fit.camera_raw_rms.push_back(thinned.empty() ? 0.0 : std::sqrt(change / static_cast<double>(thinned.size())));
    const std::vector<double> p = moved.model->Flat();
    for (std::size_t i = 0; i < np; ++i)
      for (std::size_t j = 0; j < np; ++j) cameras[i][j] += (p[i] - fit.parameters[i]) * (p[j] - fit.parameters[j]);
  }
  return cameras;
}

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

void SetCovariance(const Matrix& samples_part, const Matrix& cameras, const std::vector<bool>& unidentified,
                   DepthFit& fit) {
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
  fit.unidentified.clear();
  for (std::size_t i = 0; i < np && i < unidentified.size(); ++i) {
    if (!unidentified[i] || frozen[i]) continue;
    const double none = std::numeric_limits<double>::quiet_NaN();
    fit.sigma[i] = fit.sigma_samples[i] = fit.sigma_cameras[i] = none;
    fit.unidentified.push_back(i);
  }
}

}  // namespace speckle::fitting
