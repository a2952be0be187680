#include "pipeline/model_lab.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "pipeline/verdict_text.h"
#include "schemas/errors.h"
#include "stages/step_clock.h"

namespace speckle {

// The undistortion grid is chosen automatically when it cuts the boards'
// held-out RMS by at least this share, the bar a diagnosis candidate must
// clear too. A grid learned from walls that show no billowing (stock optics,
// or a wide-angle room whose walls gave it nothing) wins a percent by chance
// and can move the image centre's far depths by percents where no board
// checked it (a randomized wide-angle room: 0.273 -> 0.270 raw held out, and
// depth 6 % off at 2.5 m).
constexpr double kMinGridGain = 0.03;

// A millimetre sensor's residuals are in the millimetres it reads, not in
// raw disparity; the verdict says which (DiagnosisOptions::reading_unit).
DiagnosisOptions DiagnosisFor(DepthUnits units) {
  DiagnosisOptions options;
  if (units == DepthUnits::kMillimetre) options.reading_unit = "mm read";
  return options;
}

ModelLab RunModelLab(ModelLabInput in) {
  const StepClock lab_clock;
  ModelLab lab;
  std::vector<PairedSample>& undistorted = lab.undistorted;
  if (in.grid) {
    undistorted = in.samples;
    for (auto& s : undistorted) s.raw = in.grid->Apply(s.raw, s.x, s.y);
  }
  // The spec's model, and for comparison the other base forms without
  // effects. Raw disparities take the disparity forms; drivers that report
  // millimetres (OpenNI) take the linear form (thesis App. C).
  std::vector<model::ModelDefinition> definitions{in.spec.Definition()};
  if (in.units != DepthUnits::kMillimetre) {
    for (model::BaseForm form : {model::BaseForm::kReciprocal, model::BaseForm::kTangent, model::BaseForm::kDisparity})
      if (form != in.spec.base_form || !in.spec.effects.empty()) definitions.push_back({form, {}});
  }
  DepthFitOptions fit_options;
  fit_options.huber_raw = in.spec.huber_raw;
  std::string why_not = "too few samples for its parameters";
  spdlog::info("fitting {} model(s) over {} samples, each held out by pose", definitions.size(), in.samples.size());
  const StepClock fits_clock;
  const int fit_count = static_cast<int>(definitions.size()) * (in.grid ? 2 : 1);
  int fit_number = 0;
  for (const auto& definition : definitions) {
    // The same model with effects on the undistorted samples starts where it
    // ended on the raw ones: the grid moves raw values by a few units, so the
    // fit lands in a few iterations instead of starting a 354-control field
    // from zero (Herrera's set: 150 s -> see README). A bare base form fits in
    // milliseconds, and the tangent form's flat valley would end elsewhere.
    fit_options.start.reset();
    for (bool with_grid : {false, true}) {
      if (with_grid && !in.grid) continue;
      // Camera uncertainty only for the spec's model: the others are comparisons.
      const bool wanted = definition.Describe() == in.spec.Definition().Describe();
      fit_options.progress = fmt::format("fit {} of {} ({}{})", ++fit_number, fit_count, definition.Describe(),
                                         with_grid ? " +undistortion" : "");
      auto fit = RunDepthModelFit(fit_options, definition, with_grid ? undistorted : in.samples,
                                  wanted ? in.perturbations : DepthPerturbations{});
      if (!Accepted(fit)) {
        if (wanted) why_not = std::get<Rejection>(fit).reason;
        continue;
      }
      lab.fits.push_back(
          {definition.Describe() + (with_grid ? " +undistortion" : ""), with_grid, std::get<DepthFit>(fit)});
      spdlog::info("{}: {:.1f} s ({})", lab.fits.back().name, lab.fits.back().fit.seconds.total,
                   lab.fits.back().fit.solver_report);
      if (!definition.effects.empty()) fit_options.start = WarmStartFrom(lab.fits.back().fit);
    }
  }
  lab.fits_seconds = fits_clock.Seconds();
  int without = -1, with = -1;
  const std::string wanted = in.spec.Definition().Describe();
  for (int i = 0; i < static_cast<int>(lab.fits.size()); ++i) {
    if (lab.fits[i].fit.definition.Describe() != wanted) continue;
    (lab.fits[i].undistorted ? with : without) = i;
  }
  if (without < 0) throw InputError("the model " + wanted + " could not be fitted: " + why_not);
  lab.chosen = without;
  if (with >= 0 &&
      (in.spec.undistortion == UndistortionUse::kOn ||
       (in.spec.undistortion == UndistortionUse::kAuto &&
        lab.fits[with].fit.held_out_raw.rms < (1 - kMinGridGain) * lab.fits[without].fit.held_out_raw.rms))) {
    lab.chosen = with;
  }
  lab.samples = std::move(in.samples);
  if (!lab.Chosen().undistorted) std::vector<PairedSample>().swap(undistorted);
  spdlog::info("diagnosis: residuals against every covariate, then every catalogue effect tried on its own");
  lab.diagnosis = RunModelDiagnosis(DiagnosisFor(in.units), lab.ChosenSamples(), lab.Chosen().fit, in.perturbations);
  lab.verdict = VerdictText(lab.diagnosis, in.session);
  lab.next_steps = NextStepsJson(lab.diagnosis, in.session);
  lab.seconds = lab_clock.Seconds();
  return lab;
}

}  // namespace speckle
