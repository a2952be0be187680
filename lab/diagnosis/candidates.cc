#include "lab/diagnosis/candidates.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "lab/diagnosis/floor.h"
#include "lab/stats/pose_tests.h"
#include "model/effect.h"
#include "stages/step_clock.h"

namespace speckle {
namespace {

// The covariates (model/covariates.h names) that take one value over every
// sample: an effect reading only those is one offset, the base form's.
std::set<std::string> ConstantCovariates(const std::vector<PairedSample>& samples) {
  std::set<std::string> constant;
  if (samples.empty()) return constant;
  const model::Covariates first = CovariatesOf(samples.front());
  for (const auto& field : model::kCovariateFields) constant.insert(field.name);
  for (const auto& s : samples) {
    const model::Covariates c = CovariatesOf(s);
    for (const auto& field : model::kCovariateFields)
      if (c.*field.field != first.*field.field) constant.erase(field.name);
  }
  return constant;
}

// The current model with two candidates' changes: both effects, or an
// effect and another base form. Empty when they are the same change.
std::optional<model::ModelDefinition> CombinedModel(const model::ModelDefinition& current,
                                                    const model::ModelDefinition& first,
                                                    const model::ModelDefinition& second) {
  model::ModelDefinition both = first;
  if (second.form != current.form) both.form = second.form;
  for (const auto& e : second.effects) {
    bool present = false;
    for (const auto& f : both.effects) present = present || f.name == e.name;
    if (!present) both.effects.push_back(e);
  }
  if (both.Describe() == first.Describe()) return std::nullopt;
  return both;
}

// What a candidate is and which covariates it reads, from the catalogue.
void Describe(Candidate& c) {
  if (c.name.rfind("base_form:", 0) == 0) {
    c.doc = "another base form for the raw-to-depth relation";
    return;
  }
  for (const auto& info : model::EffectCatalogue()) {
    if (info.name != c.name) continue;
    c.doc = info.doc;
    c.reads = info.create()->CovariatesRead();
  }
}

// Where the held-out residuals depart from the floor: the floor itself, the
// poses' coverage, every covariate's profile (by sample, and by pose mean for
// the pose-level axes, most explaining first) and the best raw step.

// How much better `with` predicts the held-out samples than `reference`:
// the share of RMS it removes and the per-pose gain's significance.
struct Gain {
  double reduction = 0, significance = 0, p_value = 1;
  ReductionInterval interval;  // the reduction's 90 % interval over poses
  int poses_better = 0, poses = 0;
  bool any = false;
};

Gain GainOver(const std::vector<PairedSample>& subset, const std::vector<double>& reference,
              const std::vector<double>& with) {
  std::map<int, double> gain_by_pose;
  std::map<int, std::pair<double, double>> squares_by_pose;  // without, with
  double current = 0, next = 0;
  Gain g;
  for (std::size_t j = 0; j < subset.size(); ++j) {
    const double a = reference[j], b = with[j];
    if (!std::isfinite(a) || !std::isfinite(b)) continue;
    current += a * a, next += b * b, g.any = true;
    gain_by_pose[subset[j].pose] += a * a - b * b;
    squares_by_pose[subset[j].pose].first += a * a;
    squares_by_pose[subset[j].pose].second += b * b;
  }
  if (g.any && current > 0) g.reduction = 1 - std::sqrt(next / current);
  g.significance = MeanGainSignificance(gain_by_pose);
  // Each pose counts once, as the log of its RMS ratio: a far pose whose
  // error halves weighs as much as a near one whose error halves.
  std::vector<double> log_ratio;
  for (const auto& [pose, sq] : squares_by_pose) {
    if (!(sq.first > 0) || !(sq.second > 0)) continue;
    log_ratio.push_back(0.5 * std::log(sq.first / sq.second));
    g.poses_better += log_ratio.back() > 0;
  }
  g.poses = static_cast<int>(log_ratio.size());
  g.p_value = SignedRankPValue(log_ratio);
  std::vector<std::pair<double, double>> squares;
  for (const auto& [pose, sq] : squares_by_pose) squares.push_back(sq);
  g.interval = PoseBootstrapReduction(squares);
  return g;
}

// A model held out where the comparison holds models out.
StageResult<HeldOutFit> HoldOut(const Comparison& in, const model::ModelDefinition& definition) {
  return in.Judged(definition) ? in.judge(definition, in.subset, false)
                               : RunHeldOutFit(in.candidate_options, definition, in.subset, in.perturbations);
}

// What a model held out where `definition` is is compared with.
const std::vector<double>& Reference(const Comparison& in, const model::ModelDefinition& definition) {
  return in.judge && !in.Judged(definition) ? in.depth_fit_baseline : in.baseline;
}

// Why a joint hold-out's floor cannot be trusted, if it cannot: a held-out
// prediction's sigma is a part of its held-out error (error^2 = noise^2 +
// sigma^2 + misfit^2), so a sigma well above that error means the folds'
// covariance is near singular (freeing Herrera's depth lens gave a floor of
// 3803 raw against a held-out error of about 1, and a verdict of complete).
std::optional<std::string> UntrustedJointFloor(const DiagnosisOptions& options, double sigma_rms, double held_out_rms) {
  if (!(held_out_rms > 0) || !std::isfinite(held_out_rms))
    return fmt::format("the joint hold-out's error is not finite ({})", held_out_rms);
  if (!std::isfinite(sigma_rms) || sigma_rms > options.max_joint_sigma_ratio * held_out_rms)
    return fmt::format(
        "the joint hold-out's floor is not trusted: its held-out predictions' sigma ({:.3g} raw rms) is over {} times "
        "their error ({:.3g} raw rms), so some fold's cameras are not pinned without its poses",
        sigma_rms, options.max_joint_sigma_ratio, held_out_rms);
  return std::nullopt;
}

// The current model held out by the judge (the joint problem): its error
// there is what the candidates must beat and what the floor is compared
// with. When it cannot be held out there, the candidates are judged in the
// depth fit instead (said).
void CurrentModelJudged(const DiagnosisOptions& options, const DepthFit& fit, Comparison& in, Diagnosis& d) {
  const StepClock current_clock;
  const auto judged = in.judge(fit.definition, in.subset, true);
  d.seconds.current_refit = current_clock.Seconds();
  if (!Accepted(judged)) {
    d.joint_declined = fmt::format("the current model could not be held out in the joint calibration ({})",
                                   std::get<Rejection>(judged).reason);
    spdlog::warn("{}; the candidates are judged in the depth fit with the cameras held", d.joint_declined);
    in.judge = nullptr;
    return;
  }
  const HeldOutFit& held = std::get<HeldOutFit>(judged);
  const double rms = Summarize(held.held_out_residual_raw).rms;
  // A held-out board is placed by its colour corners and outline alone and
  // the cameras are fitted without its depths, so its predicted raw is less
  // certain than the joint fit's: that is the floor's truth part here.
  const double part = held.held_out_prediction_sigma_raw.size() == in.subset.size()
                          ? Summarize(held.held_out_prediction_sigma_raw).rms
                          : 0;
  if (const auto untrusted = UntrustedJointFloor(options, part, rms)) {
    spdlog::warn("{}; the candidates are judged in the depth fit with the cameras held", *untrusted);
    d.joint_declined = *untrusted;
    in.judge = nullptr;
    return;
  }
  in.baseline = held.held_out_residual_raw;
  if (part > 0) {
    d.floor.colour_pose_raw = part;
    d.floor.cameras_raw = 0;  // in the prediction's sigma already
    SumFloorParts(d.floor);
    d.floor.source +=
        " (each held-out board placed by its colour corners and outline, the cameras fitted to the other poses)";
  }
  if (d.held_out_rms > 0) d.held_out_mm *= rms / d.held_out_rms;
  d.held_out_rms = rms;
  d.ratio_to_floor = d.floor.floor_raw > 0 ? rms / d.floor.floor_raw : 0;
  d.complete = d.ratio_to_floor <= options.complete_ratio;
  d.judged_jointly = true;
  d.principal_point_from_depth_image = held.principal_point_from_depth_image;
}

// The current model held out in the depth fit; the baseline too unless the
// joint problem gave it.
void CurrentModelRefit(const DepthFit& fit, Comparison& in, Diagnosis& d) {
  std::vector<double>& baseline = in.judge ? in.depth_fit_baseline : in.baseline;
  baseline.assign(in.subset.size(), std::nan(""));
  const StepClock current_clock;
  if (const auto refit = RunHeldOutFit(in.fit_options, fit.definition, in.subset); Accepted(refit)) {
    baseline = std::get<HeldOutFit>(refit).held_out_residual_raw;
  } else {
    for (std::size_t j = 0; j < in.chosen.size(); ++j) baseline[j] = fit.held_out_residual_raw[in.chosen[j]];
  }
  if (!in.judge) d.seconds.current_refit = current_clock.Seconds();
}

// Sets in.cameras_free and the cameras' shifts; their share of the error
// is compared with the current model's once both are known.
void FitWithCamerasFree(const DiagnosisOptions& options, const DepthFit& fit, Comparison& in, Diagnosis& d) {
  const StepClock cameras_clock;
  if (!in.perturbations.empty()) {
    DepthFitOptions free_options = in.fit_options;
    free_options.camera_freedom_sigma = options.camera_freedom_sigma;
    if (const auto r = RunDepthModelFit(free_options, fit.definition, in.subset, in.perturbations); Accepted(r)) {
      const DepthFit& free_fit = std::get<DepthFit>(r);
      in.cameras_free = free_fit.held_out_residual_raw;
      d.camera_shift_sigma = free_fit.camera_shift_sigma;
    }
  }
  d.seconds.cameras_free = cameras_clock.Seconds();
}

// With the cameras free, the model is judged on what it leaves beyond them
// (DiagnosisOptions::judge_beyond_cameras): its held-out error with the
// cameras free against the floor without their part.
void JudgeBeyondCameras(const DiagnosisOptions& options, Diagnosis& d) {
  if (!options.judge_beyond_cameras || !(d.floor.beyond_cameras_raw > 0)) return;
  d.judged_beyond_cameras = true;
  d.ratio_to_floor = *d.cameras_free_held_out_rms / d.floor.beyond_cameras_raw;
  d.complete = d.ratio_to_floor <= options.complete_ratio;
}

// A fitted candidate's gain over the current model, and beyond the cameras.
void JudgeCandidate(const Comparison& in, const model::ModelDefinition& definition,
                    const StageResult<HeldOutFit>& result, const Diagnosis& d, Candidate& c) {
  if (!Accepted(result)) {
    c.not_fitted = std::get<Rejection>(result).reason;
    return;
  }
  const HeldOutFit& candidate = std::get<HeldOutFit>(result);
  // Judged beyond the cameras, both sides move the cameras: the gain is
  // what the effect explains that the cameras' uncertainty does not.
  const bool beyond_cameras = d.judged_beyond_cameras && in.cameras_free;
  c.held_out_jointly = d.judged_jointly && in.Judged(definition);
  const Gain g = GainOver(in.subset, beyond_cameras ? *in.cameras_free : Reference(in, definition),
                          candidate.held_out_residual_raw);
  if (!g.any) {
    c.not_fitted = "no held-out sample to compare with the current model";
    return;
  }
  c.parameters = static_cast<int>(candidate.parameters);
  c.reduction = g.reduction;
  // In mm, the same share of the plain fit's mm (as the raw RMS scales).
  const double scale = beyond_cameras ? *d.cameras_free_held_out_rms / d.held_out_rms : 1.0;
  c.held_out_rms = d.held_out_rms * scale * (1 - c.reduction);
  c.held_out_mm = d.held_out_mm * scale * (1 - c.reduction);
  if (g.poses >= 3) {
    c.held_out_interval_raw = {d.held_out_rms * scale * (1 - g.interval.high),
                               d.held_out_rms * scale * (1 - g.interval.low)};
  }
  c.significance = g.significance;
  c.p_value = g.p_value;
  c.poses_better = g.poses_better;
  c.poses_compared = g.poses;
  const Gain beyond =
      in.cameras_free && !beyond_cameras ? GainOver(in.subset, *in.cameras_free, candidate.held_out_residual_raw) : g;
  c.reduction_beyond_cameras = beyond.reduction;
  c.significance_beyond_cameras = beyond.significance;
  c.p_value_beyond_cameras = beyond.p_value;
}

}  // namespace

bool Comparison::Judged(const model::ModelDefinition& definition) const {
  return judge && model::DepthModel(definition).Flat().size() <= max_judged_parameters;
}

CandidateModelList CandidateModels(const model::ModelDefinition& current, const std::vector<PairedSample>& samples) {
  CandidateModelList out;
  // A millimetre session is fitted in linear_mm, a raw one in a disparity form.
  const bool millimetre = current.form == model::BaseForm::kLinearMm;
  const std::set<std::string> constant = ConstantCovariates(samples);
  for (const auto& info : model::EffectCatalogue()) {
    bool present = false;
    for (const auto& e : current.effects) present = present || e.name == info.name;
    const auto reads = info.create()->CovariatesRead();
    const bool blind = std::all_of(reads.begin(), reads.end(), [&](const auto& r) { return constant.count(r); });
    if (present || !info.AppliesTo(millimetre) || blind) continue;
    model::ModelDefinition d = current;
    model::EffectSpec effect;
    effect.name = info.name;
    d.effects.push_back(effect);
    out.emplace_back(info.name, d);
  }
  if (current.form != model::BaseForm::kLinearMm) {
    for (model::BaseForm form : {model::BaseForm::kReciprocal, model::BaseForm::kTangent}) {
      if (form == current.form) continue;
      model::ModelDefinition d = current;
      d.form = form;
      out.emplace_back(std::string("base_form:") + model::Info(form).name, d);
    }
  }
  return out;
}

Comparison ComparisonSubset(const DiagnosisOptions& options, const DepthFit& fit,
                            const std::vector<PairedSample>& samples, const DepthPerturbations& perturbations,
                            const HeldOutJudge& judge) {
  Comparison in;
  in.judge = judge;
  in.max_judged_parameters = options.max_jointly_judged_parameters;
  const std::size_t stride = EvenStride(samples.size(), options.max_candidate_samples);
  for (std::size_t i = 0; i < samples.size(); i += stride) in.chosen.push_back(i);
  for (std::size_t i : in.chosen) in.subset.push_back(samples[i]);
  in.perturbations.in_floor = perturbations.in_floor;
  for (const auto& depths : perturbations.depths) {
    std::vector<double>& moved = in.perturbations.depths.emplace_back();
    for (std::size_t i : in.chosen) moved.push_back(depths[i]);
  }
  in.fit_options.folds = options.folds;
  in.fit_options.millimetre_readings = fit.millimetre_readings;  // candidates weigh samples as the fit did
  in.fit_options.max_iterations = 30;  // a ranking needs the error to a few per cent, not the last digit
  in.candidate_options = in.fit_options;
  if (options.judge_beyond_cameras) in.candidate_options.camera_freedom_sigma = options.camera_freedom_sigma;
  return in;
}

std::map<std::string, std::vector<double>> FitCandidates(
    const DiagnosisOptions& options, const std::vector<std::pair<std::string, model::ModelDefinition>>& models,
    const DepthFit& fit, Comparison& in, Diagnosis& d) {
  d.candidates.resize(models.size());
  std::vector<std::optional<StageResult<HeldOutFit>>> results(models.size());
  const StepClock candidates_clock;
  if (in.judge) CurrentModelJudged(options, fit, in, d);
  std::optional<StepProgress> progress(std::in_place,
                                       in.judge ? "diagnosis: candidate held out jointly" : "diagnosis: candidate",
                                       static_cast<int>(models.size()));
  // Largest first: the pattern's folds take most of the time, and started
  // last they ran on one core while the other was idle.
  std::vector<std::size_t> order(models.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return model::DepthModel(models[a].second).Flat().size() > model::DepthModel(models[b].second).Flat().size();
  });
  tbb::parallel_invoke(
      [&] {
        tbb::parallel_for(std::size_t{0}, models.size(), [&](std::size_t i) {
          const std::size_t k = order[i];
          const StepClock clock;
          results[k] = HoldOut(in, models[k].second);
          d.candidates[k].seconds = clock.Seconds();
          progress->Done(models[k].first);
        });
      },
      [&] {
        CurrentModelRefit(fit, in, d);
        if (!in.judge) FitWithCamerasFree(options, fit, in, d);  // the joint problem frees the cameras itself
      });
  progress.reset();
  d.seconds.candidates = candidates_clock.Seconds();
  if (in.cameras_free) {
    d.cameras_free_held_out_rms = d.held_out_rms * (1 - GainOver(in.subset, in.baseline, *in.cameras_free).reduction);
    JudgeBeyondCameras(options, d);
  }
  std::map<std::string, std::vector<double>> held_out_with;
  for (std::size_t k = 0; k < models.size(); ++k) {
    d.candidates[k].name = models[k].first;
    Describe(d.candidates[k]);
    if (const auto* held = std::get_if<HeldOutFit>(&*results[k]))
      held_out_with[models[k].first] = held->held_out_residual_raw;
    JudgeCandidate(in, models[k].second, *results[k], d, d.candidates[k]);
  }
  return held_out_with;
}

// Fitted candidates first, best first; those not fitted keep their order.
// Among those near the best, the one with fewest parameters leads.
void RankCandidates(const DiagnosisOptions& options, Diagnosis& d) {
  std::stable_sort(d.candidates.begin(), d.candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.Fitted() != b.Fitted() ? a.Fitted() : a.Fitted() && a.reduction > b.reduction;
  });
  if (d.candidates.empty()) return;
  const double near_best = d.candidates.front().held_out_rms * (1 + options.parsimony_share);
  auto simplest = d.candidates.begin();
  for (auto c = d.candidates.begin(); c != d.candidates.end(); ++c)
    if (c->Fitted() && c->reduction >= options.min_reduction && c->held_out_rms <= near_best &&
        c->parameters < simplest->parameters)
      simplest = c;
  std::rotate(d.candidates.begin(), simplest, simplest + 1);
}

// One effect not enough: the recommended one with each other helpful
// candidate, judged against the recommended one alone by the same test.
void SearchPairs(const DiagnosisOptions& options, const model::ModelDefinition& current,
                 const std::vector<std::pair<std::string, model::ModelDefinition>>& models, const Comparison& in,
                 const std::vector<double>& single, Diagnosis& d) {
  const auto recommended_model =
      std::find_if(models.begin(), models.end(), [&](const auto& m) { return m.first == *d.recommended; });
  std::vector<std::pair<std::string, model::ModelDefinition>> pairs;
  for (const auto& c : d.candidates) {
    if (c.recommended || c.reduction < options.min_reduction || pairs.size() >= options.max_pair_candidates) continue;
    const auto other = std::find_if(models.begin(), models.end(), [&](const auto& m) { return m.first == c.name; });
    if (other == models.end()) continue;
    // Both sides of the comparison held out in the same problem.
    auto both = CombinedModel(current, recommended_model->second, other->second);
    if (both && in.Judged(*both) == in.Judged(recommended_model->second)) pairs.emplace_back(c.name, *both);
  }
  std::vector<PairFinding> found(pairs.size());
  const StepClock pairs_clock;
  StepProgress pair_progress("diagnosis: pair", static_cast<int>(pairs.size()));
  tbb::parallel_for(std::size_t{0}, pairs.size(), [&](std::size_t k) {
    found[k].second = pairs[k].first;
    const StepClock clock;
    const auto result = HoldOut(in, pairs[k].second);
    found[k].seconds = clock.Seconds();
    pair_progress.Done(pairs[k].first);
    if (!Accepted(result)) return;
    const std::vector<double>& held_out = std::get<HeldOutFit>(result).held_out_residual_raw;
    const Gain over_single = GainOver(in.subset, single, held_out);
    const Gain over_current = GainOver(in.subset, Reference(in, pairs[k].second), held_out);
    found[k].fitted = over_single.any;
    found[k].held_out_rms = d.held_out_rms * (1 - over_current.reduction);
    found[k].reduction_over_single = over_single.reduction;
    found[k].p_value = over_single.p_value;
    found[k].poses_better = over_single.poses_better;
    found[k].poses_compared = over_single.poses;
  });
  std::erase_if(found, [](const PairFinding& f) { return !f.fitted; });
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.held_out_rms < b.held_out_rms; });
  if (!found.empty()) d.best_pair = found.front();
  d.seconds.pairs = pairs_clock.Seconds();
}

}  // namespace speckle
