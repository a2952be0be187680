#include "lab/fit/residual_blocks.h"

#include <map>
#include <memory>
#include <numeric>

#include "lab/fit/composed_residual.h"
#include "stages/ceres_blocks.h"

namespace speckle::fitting {
namespace {

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

}  // namespace

std::vector<bool> SplitEffects(const DepthFitOptions& options, const model::DepthModel& m) {
  std::vector<bool> split(m.Effects().size(), false);
  if (!options.split_by_support || m.Flat().size() < options.sparse_from_parameters) return split;
  for (std::size_t k = 0; k < split.size(); ++k) split[k] = m.Effects()[k]->GivesSupport();
  return split;
}

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
      for (const auto& moved : freedom->perturbations->depths) shift.push_back(moved[index] - s.depth_m);
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

std::vector<ceres::ResidualBlockId> ConstrainEffects(const model::ModelDefinition& definition,
                                                     const model::DepthModel& m,
                                                     const std::vector<double*>& effect_blocks,
                                                     const std::vector<bool>& split, ceres::Problem& problem) {
  std::vector<ceres::ResidualBlockId> priors;
  for (std::size_t k = 0; k < m.Effects().size(); ++k) {
    const auto& parameters = m.Effects()[k]->Parameters();
    const int blocks = split[k] ? static_cast<int>(parameters.size()) : 1;
    for (int b = 0; b < blocks; ++b) {
      double* block = effect_blocks[k] + b;
      if (definition.effects[k].frozen) {
        HoldConstant(problem, block);
        continue;
      }
      const auto first = parameters.begin() + b;
      const std::vector<model::EffectParameter> own(first, split[k] ? first + 1 : parameters.end());
      bool prior = false;
      for (const auto& p : own) prior = prior || p.prior_sigma > 0;
      if (prior) priors.push_back(problem.AddResidualBlock(new PriorCost(own), nullptr, block));
      for (std::size_t i = 0; i < own.size(); ++i)
        BoundParameter(problem, block, static_cast<int>(i), own[i].lower, own[i].upper);
    }
  }
  return priors;
}

void ConstrainEffects(const model::ModelDefinition& definition, const std::vector<bool>& split, Solved& out) {
  ConstrainEffects(definition, *out.model, std::vector<double*>(out.blocks.begin() + 1, out.blocks.end()), split,
                   *out.problem);
}

}  // namespace speckle::fitting
