#pragma once
// A depth sample's residual in the joint problem with the model's effects:
// SampleRaw's (the base form at the depth where the pixel's ray meets the
// board plane, differentiated through the cameras and the pose) less the
// effects' offsets, each with its own gradient. Fitted with the base form
// alone, the cameras and poses take up what the model lacks (the hunt
// benchmark's --joint-cameras table, bench/results/hunt.md); with the
// effect in the problem they need not.
#include <ceres/ceres.h>

#include <memory>
#include <vector>

#include "lab/fit/fit_samples.h"
#include "lab/joint/chained_costs.h"
#include "model/depth_model.h"

namespace speckle::joint {

// Blocks: pose 6, rotation 3, translation 3, depth k 4, depth lens 5, base
// base_size, billow 2, then one block per effect (its whole parameters).
class SampleRawWithEffects : public ceres::CostFunction {
 public:
  // The model and the sample must outlive the residual.
  SampleRawWithEffects(const SampleRaw& geometry, std::size_t base_size, const model::DepthModel* model,
                       const PairedSample* sample)
      : model_(model), covariates_(FitCovariatesOf(*sample)), sigma_(geometry.sigma) {
    geometry_ = std::make_unique<SampleRawCost>(geometry, static_cast<int>(base_size));
    set_num_residuals(1);
    *mutable_parameter_block_sizes() = geometry_->parameter_block_sizes();
    for (std::size_t k = 0; k < model->Effects().size(); ++k)
      mutable_parameter_block_sizes()->push_back(static_cast<int>(model->EffectParameters(k).size()));
  }

  bool Evaluate(double const* const* blocks, double* residual, double** jacobians) const override {
    if (!geometry_->Evaluate(blocks, residual, jacobians)) return false;
    constexpr std::size_t kGeometryBlocks = 7;
    for (std::size_t k = 0; k < model_->Effects().size(); ++k) {
      const model::Effect& effect = *model_->Effects()[k];
      double* gradient = jacobians ? jacobians[kGeometryBlocks + k] : nullptr;
      const double offset = gradient ? effect.RawOffset(blocks[kGeometryBlocks + k], covariates_, gradient)
                                     : effect.RawOffset(blocks[kGeometryBlocks + k], covariates_);
      residual[0] -= offset / sigma_;
      for (std::size_t i = 0; gradient && i < effect.Parameters().size(); ++i) gradient[i] /= -sigma_;
    }
    return std::isfinite(residual[0]);
  }

 private:
  std::unique_ptr<ceres::CostFunction> geometry_;
  const model::DepthModel* model_;
  model::Covariates covariates_;
  double sigma_;
};

}  // namespace speckle::joint
