#include "lab/fit/cross_validation.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <optional>

#include "stages/step_clock.h"

namespace speckle::fitting {

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

}  // namespace speckle::fitting
