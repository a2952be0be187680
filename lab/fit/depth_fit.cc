#include "lab/fit/depth_fit.h"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "lab/fit/covariance.h"
#include "lab/fit/cross_validation.h"
#include "lab/fit/fit_checks.h"
#include "lab/fit/solve.h"
#include "stages/step_clock.h"

namespace speckle {

using namespace fitting;  // the fit's parts (solve, covariance, folds, checks)

WarmStart WarmStartFrom(const DepthFit& fit) {
  const model::DepthModel m = fit.Model();
  WarmStart start{fit.definition.form, m.Base(), {}};
  for (std::size_t k = 0; k < m.Effects().size(); ++k)
    if (!fit.definition.effects[k].frozen) start.effects[fit.definition.effects[k].name] = m.EffectParameters(k);
  return start;
}

model::DepthModel DepthFit::Model() const {
  model::DepthModel m(definition);
  m.SetFlat(parameters);
  return m;
}

namespace {

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

// The fit of every sample, its residuals, covariance and camera refits
// (everything but the folds) into fit; a rejection when it cannot be used.
std::optional<Rejection> FitAllSamples(const DepthFitOptions& options, const model::ModelDefinition& definition,
                                       const std::vector<PairedSample>& samples,
                                       const DepthPerturbations& perturbations, const CameraFreedom* free_cameras,
                                       DepthFit& fit, Matrix& independent, std::vector<bool>& unidentified,
                                       Matrix& cameras, FitSeconds& seconds) {
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
  independent = IndependentCovariance(options, solved, samples, free_cameras, variance, &unidentified);
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
  if (auto invalid = InvalidOptions(options)) return *invalid;
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
  std::vector<bool> unidentified;
  std::optional<Rejection> rejection;
  std::vector<std::vector<double>> fold_parameters;
  tbb::parallel_invoke(
      [&] {
        rejection = FitAllSamples(options, definition, samples, perturbations, free_cameras, fit, independent,
                                  unidentified, cameras, seconds);
      },
      [&] {
        fold_parameters = HoldOutPoses(options, definition, samples, perturbations, free_cameras, folds, seconds);
      });
  if (rejection) return *rejection;
  fit.held_out_residual_raw = std::move(folds.held_out_residual_raw);
  fit.held_out_raw = folds.held_out_raw;
  fit.held_out_mm = folds.held_out_mm;
  fit.millimetre_readings = options.millimetre_readings;
  if (auto unjudgeable = Unjudgeable(fit, samples)) return *unjudgeable;
  SetCovariance(SamplesCovariance(independent, fold_parameters), cameras, unidentified, fit);
  seconds.total = total_clock.Seconds();
  fit.seconds = std::move(seconds);
  return fit;
}

StageResult<HeldOutFit> RunHeldOutFit(const DepthFitOptions& options, const model::ModelDefinition& definition,
                                      const std::vector<PairedSample>& measured,
                                      const DepthPerturbations& perturbations) {
  if (auto invalid = InvalidOptions(options)) return *invalid;
  FitSeconds seconds;
  const std::vector<PairedSample> with_fit_raw = WithFitRaw(options, definition, measured, seconds);
  const std::vector<PairedSample>& samples = with_fit_raw.empty() ? measured : with_fit_raw;
  if (auto rejection = Unfittable(definition, samples)) return *rejection;
  DepthFit folds;  // only its held-out fields are filled
  folds.parameters = model::DepthModel(definition).Flat();
  const CameraFreedom freedom{&perturbations, samples.data(), options.camera_freedom_sigma};
  const CameraFreedom* free_cameras = options.camera_freedom_sigma > 0 && !perturbations.empty() ? &freedom : nullptr;
  HoldOutPoses(options, definition, samples, perturbations, free_cameras, folds, seconds);
  if (auto rejection = Unjudgeable(folds, samples)) return *rejection;
  return HeldOutFit{std::move(folds.held_out_residual_raw), folds.held_out_raw, folds.parameters.size()};
}

}  // namespace speckle
