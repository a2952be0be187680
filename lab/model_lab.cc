#include "lab/model_lab.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <iterator>
#include <stdexcept>

#include "lab/diagnosis/verdict_text.h"
#include "schemas/errors.h"
#include "stages/step_clock.h"

namespace speckle {

namespace {

// What each model is fitted with: its definitions and the shared options.
struct LabPlan {
  std::vector<model::ModelDefinition> definitions;  // the spec's first, then the comparisons
  DepthFitOptions options;
};

LabPlan PlanFits(const ModelLabInput& in) {
  LabPlan plan;
  // The spec's model, and for comparison the other base forms without
  // effects. Raw disparities take the disparity forms; drivers that report
  // millimetres (OpenNI) take the linear form (thesis App. C).
  plan.definitions.push_back(in.spec.Definition());
  if (in.units != DepthUnits::kMillimetre) {
    for (model::BaseForm form : {model::BaseForm::kReciprocal, model::BaseForm::kTangent, model::BaseForm::kDisparity})
      if (form != in.spec.base_form || !in.spec.effects.empty()) plan.definitions.push_back({form, {}});
  }
  plan.options.huber_raw = in.spec.huber_raw;
  // A millimetre sensor's residuals are in the millimetres it reads; the
  // fits carry that to the diagnosis and the verdict (DepthFit::millimetre_readings).
  plan.options.millimetre_readings = in.units == DepthUnits::kMillimetre;
  return plan;
}

// One model on the raw samples and, with a grid, on the undistorted ones,
// with a progress line on a terminal when `shown` (the spec's; the
// comparisons are quiet). Returns the accepted fits; why_not (when given)
// gets a rejection.
std::vector<NamedFit> FitModel(const LabPlan& plan, std::size_t k, const ModelLab& lab, bool with_grid_too,
                               const DepthPerturbations& perturbations, bool shown, std::string* why_not) {
  const model::ModelDefinition& definition = plan.definitions[k];
  DepthFitOptions options = plan.options;
  std::vector<NamedFit> fits;
  for (bool with_grid : {false, true}) {
    if (with_grid && !with_grid_too) continue;
    if (shown)
      options.progress = fmt::format("fit {} of {} ({}{})", with_grid ? 2 : 1, with_grid_too ? 2 : 1,
                                     definition.Describe(), with_grid ? " +undistortion" : "");
    auto fit = RunDepthModelFit(options, definition, with_grid ? lab.undistorted : lab.samples, perturbations);
    if (!Accepted(fit)) {
      if (why_not) *why_not = std::get<Rejection>(fit).reason;
      continue;
    }
    fits.push_back({definition.Describe() + (with_grid ? " +undistortion" : ""), with_grid, std::get<DepthFit>(fit)});
    spdlog::info("{}: {:.1f} s ({})", fits.back().name, fits.back().fit.seconds.total, fits.back().fit.solver_report);
    // The same model with effects on the undistorted samples starts where it
    // ended on the raw ones: the grid moves raw values by a few units, so the
    // fit lands in a few iterations instead of starting a 354-control field
    // from zero (Herrera's set: see bench/results/speed.md). A bare base form fits in
    // milliseconds, and the tangent form's flat valley would end elsewhere.
    if (!definition.effects.empty()) options.start = WarmStartFrom(fits.back().fit);
  }
  return fits;
}

// The spec's fit without the grid, or with it where it cuts the held-out
// error by min_gain (or the spec asks for it): the bar a diagnosis candidate
// must clear too (DiagnosisOptions::min_reduction). A grid learned from walls
// that show no billowing (stock optics, or a wide-angle room whose walls gave
// it nothing) wins a percent by chance and can move the image centre's far
// depths by percents where no board checked it.
int ChooseFit(const ModelSpec& spec, const std::vector<NamedFit>& fits, double min_gain) {
  int without = -1, with = -1;
  for (int i = 0; i < static_cast<int>(fits.size()); ++i) (fits[i].undistorted ? with : without) = i;
  if (with >= 0 && (spec.undistortion == UndistortionUse::kOn ||
                    (spec.undistortion == UndistortionUse::kAuto &&
                     fits[with].fit.held_out_raw.rms < (1 - min_gain) * fits[without].fit.held_out_raw.rms)))
    return with;
  return without;
}

// The grid's standard error at each sample the chosen fit saw, looked up
// where the grid was applied (the measured raw value); empty without it.
std::vector<double> GridStdErrors(const std::optional<UndistortionGrid>& grid, const ModelLab& lab) {
  std::vector<double> out;
  if (!grid || !lab.Chosen().undistorted) return out;
  for (const auto& s : lab.samples) out.push_back(grid->StdErrorAt(s.raw, s.x, s.y));
  return out;
}

}  // namespace

ModelLab RunModelLab(ModelLabInput in) {
  const StepClock lab_clock;
  ModelLab lab;
  lab.samples = std::move(in.samples);
  if (in.grid) {
    lab.undistorted = lab.samples;
    for (auto& s : lab.undistorted) s.raw = in.grid->Apply(s.raw, s.x, s.y);
  }
  const LabPlan plan = PlanFits(in);
  const DiagnosisOptions& diagnosis_options = in.diagnosis;
  // Options are code's, not the user's: a broken rule is a defect, said
  // before any fit runs rather than as a fit's rejection.
  std::string why;
  if (!plan.options.IsValid(&why) || !diagnosis_options.IsValid(&why))
    throw std::invalid_argument("the model lab's options: " + why);
  spdlog::info("fitting {} model(s) over {} samples, each held out by pose", plan.definitions.size(),
               lab.samples.size());
  const StepClock fits_clock;
  // Camera uncertainty only for the spec's model: the others are comparisons.
  std::string why_not = "too few samples for its parameters";
  lab.fits = FitModel(plan, 0, lab, in.grid.has_value(), in.perturbations, true, &why_not);
  const bool spec_fitted =
      std::any_of(lab.fits.begin(), lab.fits.end(), [](const NamedFit& f) { return !f.undistorted; });
  if (!spec_fitted)
    throw InputError("the model " + in.spec.Definition().Describe() + " could not be fitted: " + why_not);
  lab.chosen = ChooseFit(in.spec, lab.fits, diagnosis_options.min_reduction);
  lab.spec_fits_seconds = fits_clock.Seconds();
  lab.spec_fits = static_cast<int>(lab.fits.size());
  // The comparison fits (the other base forms) and the diagnosis of the
  // chosen fit need nothing from each other: side by side, the comparisons
  // use the core the diagnosis leaves idle while its largest candidate ends
  // (bench/results/speed.md). Quiet, so that the diagnosis's progress line is
  // the one a terminal shows.
  std::vector<std::vector<NamedFit>> comparisons(plan.definitions.size());
  tbb::parallel_invoke(
      [&] {
        spdlog::info("diagnosis: residuals against every covariate, then every catalogue effect tried on its own");
        lab.diagnosis = RunModelDiagnosis(diagnosis_options, lab.ChosenSamples(), lab.Chosen().fit, in.perturbations,
                                          GridStdErrors(in.grid, lab), in.judge);
      },
      [&] {
        const StepClock comparisons_clock;
        tbb::parallel_for(std::size_t{1}, plan.definitions.size(), [&](std::size_t k) {
          comparisons[k] = FitModel(plan, k, lab, in.grid.has_value(), {}, false, nullptr);
        });
        lab.comparison_fits_seconds = comparisons_clock.Seconds();
      });
  for (auto& fits : comparisons) std::move(fits.begin(), fits.end(), std::back_inserter(lab.fits));
  if (!lab.Chosen().undistorted) std::vector<PairedSample>().swap(lab.undistorted);
  lab.verdict = VerdictText(lab.diagnosis, in.session, in.refit_tool);
  lab.next_steps = NextStepsJson(lab.diagnosis, in.session, in.refit_tool);
  lab.seconds = lab_clock.Seconds();
  return lab;
}

}  // namespace speckle
