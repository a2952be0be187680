#include "lab/diagnosis/model_diagnosis.h"

#include "lab/diagnosis/candidates.h"
#include "lab/diagnosis/covariate_profiles.h"
#include "lab/diagnosis/coverage.h"
#include "lab/diagnosis/floor.h"
#include "lab/diagnosis/verdict.h"
#include "stages/step_clock.h"

namespace speckle {
namespace {

// Where the held-out residuals depart from the floor: the floor itself, the
// poses' coverage, every covariate's profile (by sample, and by pose mean for
// the pose-level axes, most explaining first) and the best raw step.
void AnalyseResiduals(const DiagnosisOptions& options, const std::vector<PairedSample>& samples, const DepthFit& fit,
                      const std::vector<double>& grid_std_error_raw, Diagnosis& d) {
  d.floor = EstimateFloor(options, samples, fit, grid_std_error_raw);
  d.held_out_rms = fit.held_out_raw.rms;
  d.held_out_mm = fit.held_out_mm.rms;
  d.ratio_to_floor = d.floor.floor_raw > 0 ? d.held_out_rms / d.floor.floor_raw : 0;
  d.complete = d.ratio_to_floor <= options.complete_ratio;
  d.coverage = AssessCoverage(options, samples, fit, d.floor.floor_raw, d.held_out_rms);
  ProfileCovariates(options, samples, fit, d);
}

}  // namespace

Diagnosis RunModelDiagnosis(const DiagnosisOptions& options, const std::vector<PairedSample>& samples,
                            const DepthFit& fit, const DepthPerturbations& perturbations,
                            const std::vector<double>& grid_std_error_raw, const HeldOutJudge& judge) {
  const StepClock total_clock;
  Diagnosis d;
  d.reading_unit = fit.millimetre_readings ? "mm read" : "raw";
  AnalyseResiduals(options, samples, fit, grid_std_error_raw, d);
  d.seconds.residual_analysis = total_clock.Seconds();
  Comparison in = ComparisonSubset(options, fit, samples, perturbations, judge);
  const auto models = CandidateModels(fit.definition, samples);
  const auto held_out_with = FitCandidates(options, models, fit, in, d);
  RankCandidates(options, d);
  ConcludeDiagnosis(options, d);
  // A second effect is looked for only where the first leaves an excess
  // (each pair is another set of held-out fits: 3.4 of a joint diagnosis's 16 s).
  if (RecommendedLeavesExcess(options, d) && held_out_with.count(*d.recommended)) {
    SearchPairs(options, fit.definition, models, in, held_out_with.at(*d.recommended), d);
    DescribePair(options, d);
  }
  SayJointDeclined(d);
  d.seconds.total = total_clock.Seconds();
  return d;
}

}  // namespace speckle
