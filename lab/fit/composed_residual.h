#pragma once
// One sample's residual in raw units, the unit of every depth-model fit.
#include <ceres/ceres.h>

#include <vector>

#include "lab/fit/fit_samples.h"
#include "model/depth_model.h"
#include "stages/ceres_blocks.h"
#include "stages/records.h"

namespace speckle::fitting {

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

}  // namespace speckle::fitting
