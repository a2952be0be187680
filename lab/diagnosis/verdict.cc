#include "lab/diagnosis/verdict.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "lab/diagnosis/covariate_axes.h"
#include "lab/stats/pose_tests.h"

namespace speckle {
namespace {

// "u 560-640 px, v 320-400 px (pose 29); ..." for the first few sparse cells.
std::string SparseCellsText(const Coverage& c, std::size_t listed = 4) {
  std::string out;
  for (std::size_t k = 0; k < c.sparse.size() && k < listed; ++k) {
    const Coverage::Cell& cell = c.sparse[k];
    out += fmt::format("{}u {}-{} px, v {}-{} px ({} {})", k ? "; " : "", cell.u0, cell.u1, cell.v0, cell.v1,
                       cell.poses.size() == 1 ? "pose" : "poses", fmt::join(cell.poses, ", "));
  }
  if (c.sparse.size() > listed) out += fmt::format("; and {} more cells", c.sparse.size() - listed);
  return out;
}

// Where more poses help: the image cells few poses reach, when the model
// reads the image position; else over what its effects read (a drift's time
// constant wants poses spread over the recording, not over the image).
std::string SparseAdvice(const Coverage& c) {
  if (!c.ModelReadsImage())
    return c.model_reads.empty()
               ? ""
               : fmt::format(" spread over what its effects read ({})", fmt::join(c.model_reads, ", "));
  if (c.sparse.empty()) return "";
  return fmt::format(", above all where fewer than {} poses reach the image: {}", c.min_poses, SparseCellsText(c));
}

std::string Percent(double share) { return fmt::format("{:.0f} %", 100 * share); }

std::string PText(double p) { return p < 0.001 ? fmt::format("p = {:.1e}", p) : fmt::format("p = {:.3f}", p); }

// Does a covariate axis (covariate_axes.h) show what a candidate reads? A
// base form reads the raw value alone.
bool Reads(const Candidate& c, const std::string& axis_name) {
  const CovariateAxis* axis = FindCovariateAxis(axis_name);
  if (!axis) return false;
  std::vector<std::string> reads = c.reads;
  if (c.name.rfind("base_form:", 0) == 0) reads = {"raw"};
  for (const auto& r : reads)
    if (std::find(axis->shown_by.begin(), axis->shown_by.end(), r) != axis->shown_by.end()) return true;
  return false;
}

// The covariate to name: with a recommendation, the one of those it reads
// that explains most; without, the most explaining one whose pose-level test
// is clear. Findings are sorted most explaining first.
const CovariateFinding* NamedFinding(const DiagnosisOptions& options, const Diagnosis& d, const Candidate* chosen) {
  for (const auto& f : d.covariates) {
    if (!(f.explained_share > 0)) continue;
    if (chosen ? Reads(*chosen, f.covariate) : f.p_value <= options.covariate_max_p_value) return &f;
  }
  return nullptr;
}

// A formula effect along the named covariate (its axis's hint in
// covariate_axes.cc), over model/covariates.h's variables.
std::string FormulaFor(const std::string& covariate, const Diagnosis& d) {
  const CovariateAxis* axis = FindCovariateAxis(covariate);
  if (!axis) axis = FindCovariateAxis("gradient along u");
  std::string formula = axis->hint.formula;
  if (const auto at = formula.find("{level}"); at != std::string::npos)
    formula.replace(at, 7, fmt::format("{:.0f}", std::isfinite(d.step_level_raw) ? d.step_level_raw : 700.0));
  std::string parameters;
  for (const auto& [name, unit] : axis->hint.parameters)
    parameters += fmt::format(R"j({}{{"name": "{}", "unit": "{}"}})j", parameters.empty() ? "" : ", ", name, unit);
  return fmt::format(R"j({{"name": "{}", "formula": "{}", "parameters": [{}]}})j", axis->hint.name, formula,
                     parameters);
}

std::string WhereText(const DiagnosisOptions& options, const Diagnosis& d, const CovariateFinding* named) {
  if (named) {
    std::string along = named->covariate;
    if (named->level == "pose means, step" && std::isfinite(d.step_level_raw))
      along = fmt::format(
          "{} between poses (each pose's mean residual steps, with a common slope; the samples put "
          "the step near raw {:.0f})",
          named->covariate, d.step_level_raw);
    else if (named->level.rfind("pose means", 0) == 0)
      along = fmt::format("{} between poses (each pose's mean residual against its mean {})", named->covariate,
                          named->covariate);
    // With a recommendation the covariate it reads is named even when its
    // own test is not clear: say so, rather than let "vary with" claim it.
    const bool clear = named->p_value <= options.covariate_max_p_value;
    return fmt::format("residuals vary with {}{} ({} of the excess over the noise floor, {})", along,
                       clear ? "" : ", though not clearly on its own", Percent(named->explained_share),
                       PText(named->p_value));
  }
  const CovariateFinding* top = d.covariates.empty() ? nullptr : &d.covariates.front();
  if (!top || !(top->explained_share > 0)) return "residuals exceed the noise floor without a clear covariate";
  return fmt::format(
      "residuals exceed the noise floor without a clear covariate (the strongest, {}{}, explains {} "
      "of the excess at {}, short of the p = {} that makes one clear)",
      top->covariate, top->level.rfind("pose means", 0) == 0 ? " between poses" : "", Percent(top->explained_share),
      PText(top->p_value), options.covariate_max_p_value);
}

void Say(Diagnosis& d, std::string words) { d.verdict.push_back({VerdictPart::Kind::kWords, std::move(words)}); }

// Sets d.test, d.test_poses and d.poses_needed: the candidates' test in words,
// with what it takes to pass at this many poses.
void DescribeTest(const DiagnosisOptions& options, Diagnosis& d) {
  d.test_poses = 0;
  for (const auto& c : d.candidates) d.test_poses = std::max(d.test_poses, c.poses_compared);
  d.poses_needed = PosesNeededToGain(d.test_poses, options.max_p_value);
  const std::string power =
      d.poses_needed > d.test_poses
          ? fmt::format(
                "at {} poses no candidate can reach it (the smallest possible p is 2^-{} = {:.2g}): record more "
                "poses",
                d.test_poses, d.test_poses, std::pow(2.0, -d.test_poses))
      : d.poses_needed == d.test_poses
          ? fmt::format("at {} poses every one of them must gain", d.test_poses)
          : fmt::format("at {} poses it needs the {} largest per-pose changes to be gains, or more poses gaining less",
                        d.test_poses, d.poses_needed);
  d.test = fmt::format(
      "one-sided Wilcoxon signed-rank test over the {} held-out poses (each pose's RMS without and with the "
      "candidate, as a log ratio; exact sign-flip distribution), recommending at p <= {} and a cut of {} or more, or "
      "at p <= {} and a cut of {} or more (an error in a few poses); {}{}",
      d.test_poses, options.max_p_value, Percent(options.min_reduction), options.strong_max_p_value,
      Percent(options.strong_reduction), power,
      d.judged_jointly ? "; each model held out in the joint calibration (cameras, extrinsics, board poses and "
                         "model refitted without the pose's depths), so a gain is beyond what the cameras absorb"
                       : "");
}

// The first candidate (best first) that passes the test, also beyond the
// cameras' uncertainty, marked recommended; none: nullptr. `cameras_explain`:
// some candidate passed, but no better than the cameras free to move.
Candidate* Recommend(const DiagnosisOptions& options, Diagnosis& d, bool& cameras_explain) {
  cameras_explain = false;
  for (auto& c : d.candidates) {
    if (!options.PassesPoseTest(c.reduction, c.p_value)) continue;
    if (!options.PassesPoseTest(c.reduction_beyond_cameras, c.p_value_beyond_cameras)) {
      cameras_explain = true;
      continue;
    }
    c.recommended = true;
    d.recommended = c.name;
    return &c;
  }
  return nullptr;
}

// "write an effect for it as a formula ... then: <command>".
void SuggestFormula(Diagnosis& d) {
  Say(d, fmt::format("write an effect for it as a formula, e.g. {}, and add it to the current model's spec "
                     "(model_spec in its calibration.json: --model replaces the whole model; see "
                     "examples/hunt/README.md), then: ",
                     d.formula_hint));
  d.verdict.push_back({VerdictPart::Kind::kFormulaModel, ""});
}

void SayRecommended(const DiagnosisOptions& options, const std::string& where, const Candidate& c, Diagnosis& d) {
  d.conclusion = Conclusion::kAddEffect;
  const std::string from = d.judged_beyond_cameras
                               ? fmt::format("held-out RMS with the cameras free from {:.3f} {u}",
                                             *d.cameras_free_held_out_rms, fmt::arg("u", d.reading_unit))
                               : fmt::format("held-out RMS{} from {:.3f} {u} ({:.2f} mm)",
                                             d.judged_jointly ? " (each pose predicted by a joint calibration that "
                                                                "never saw its depths, the model's too)"
                                                              : "",
                                             d.held_out_rms, d.held_out_mm, fmt::arg("u", d.reading_unit));
  const std::string interval = c.held_out_interval_raw
                                   ? fmt::format(", 90 % interval {:.3f}-{:.3f} over poses",
                                                 c.held_out_interval_raw->first, c.held_out_interval_raw->second)
                                   : "";
  // A promise, not a measurement: the refit computes its own held-out
  // error, over all samples rather than the candidates' subsample.
  Say(d, fmt::format("{}; adding {} cuts {} to about {:.3f} {u} ({:.2f} mm; held out in {} pose folds{}), better on "
                     "{} of {} poses ({}) — run: ",
                     where, c.name, from, c.held_out_rms, c.held_out_mm, options.folds, interval, c.poses_better,
                     c.poses_compared, PText(c.p_value), fmt::arg("u", d.reading_unit)));
  const bool base = c.name.rfind("base_form:", 0) == 0;
  d.verdict.push_back(base ? VerdictPart{VerdictPart::Kind::kBaseForm, c.name.substr(10)}
                           : VerdictPart{VerdictPart::Kind::kAddEffect, c.name});
  const double floor = d.judged_beyond_cameras ? d.floor.beyond_cameras_raw : d.floor.floor_raw;
  const double left = floor > 0 ? c.held_out_rms / floor : 0;
  if (left <= options.complete_ratio) return;
  Say(d, fmt::format(". It explains only part: with it the error stays {:.2f} times the noise floor. If the next "
                     "verdict finds nothing more, ",
                     left));
  SuggestFormula(d);
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Within this factor of the test's cut, either side, a p value is said to be
// borderline: the flip seen on rounding was a factor of 5.
constexpr double kBorderlineFactor = 10;

// A candidate's test against the cut that applies to its cut (the strong
// one for a cut of half or more): the share of that cut its p is.
double OfItsCut(const DiagnosisOptions& options, double reduction, double p_value) {
  const double cut = reduction >= options.strong_reduction ? options.strong_max_p_value : options.max_p_value;
  return reduction >= options.min_reduction && std::isfinite(p_value) ? p_value / cut : kNaN;
}

// Candidates up to the recommended one (later ones cannot change the
// outcome), each judged on the test that decided it: the pose-level one, or
// once passed, the one beyond the cameras. The first whose p lies within
// kBorderlineFactor of its cut is said.
void SayBorderline(const DiagnosisOptions& options, Diagnosis& d) {
  for (const Candidate& c : d.candidates) {
    const double pose = OfItsCut(options, c.reduction, c.p_value);
    const double beyond = OfItsCut(options, c.reduction_beyond_cameras, c.p_value_beyond_cameras);
    const bool passed = options.PassesPoseTest(c.reduction, c.p_value);
    // Recommended: the nearer of its two passes; refused: the test it failed.
    const double share = c.recommended ? std::fmax(pose, beyond) : passed ? beyond : pose;
    if (std::isfinite(share) && share > 1 / kBorderlineFactor && share <= kBorderlineFactor) {
      const bool on_cameras = c.recommended ? beyond > pose : passed;
      d.borderline = c.name;
      Say(d, fmt::format("{}Borderline: {} ({}) cuts the held-out RMS by {:.0f} % at {}{}, within a factor of {:.0f} "
                         "of the test's cut; small changes of the inputs (cameras given rounded, another subsample "
                         "of the poses) can move it across, and more poses would settle it",
                         d.verdict.empty() ? "" : ". ", c.name, c.recommended ? "recommended" : "not recommended",
                         100 * (on_cameras ? c.reduction_beyond_cameras : c.reduction),
                         PText(on_cameras ? c.p_value_beyond_cameras : c.p_value),
                         on_cameras ? " beyond the cameras' uncertainty" : "", kBorderlineFactor));
      return;
    }
    if (c.recommended) return;
  }
}

void SayMorePoses(const std::string& where, const std::string& floor_text, Diagnosis& d) {
  const Coverage& c = d.coverage;
  d.conclusion = Conclusion::kMorePoses;
  Say(d, fmt::format(
             "{}; {}. The model fits the samples it was fitted to at {:.3f} {u} ({:.2f} times the floor) but not the "
             "poses held out: its {} parameters are more than the session's {} poses pin down, and no catalogue "
             "effect helps. Record more board poses{}, or fit a model with fewer parameters",
             where, floor_text, c.in_sample_rms, c.in_sample_rms / d.floor.floor_raw, c.parameters, c.poses,
             SparseAdvice(c), fmt::arg("u", d.reading_unit)));
}

void SayCameras(const std::string& where, const std::string& floor_text, Diagnosis& d) {
  double largest = 0;
  for (double s : d.camera_shift_sigma) largest = std::max(largest, std::abs(s));
  d.conclusion = Conclusion::kRecalibrateCameras;
  Say(d, fmt::format(
             "{}; {}. The cameras' own calibration uncertainty explains it: with the cameras moved by at most {:.1f} "
             "sigma the held-out RMS is {:.3f} {u}, and no catalogue effect does better than that. Recalibrate the "
             "cameras (more chessboard views, more tilt, the board nearer the image corners) rather than add an effect",
             where, floor_text, largest, *d.cameras_free_held_out_rms, fmt::arg("u", d.reading_unit)));
}

// Complete against a floor that is mostly the cameras' uncertainty says less:
// an effect smaller than that uncertainty cannot be seen, and the words say
// so (a wide-angle user without an IR chessboard recording got "complete" at
// 0.54 of a floor whose cameras' part was 0.41 of 0.49 raw).
void SayComplete(const std::string& floor_text, Diagnosis& d) {
  const NoiseFloor& f = d.floor;
  const bool cameras_dominate = !d.judged_beyond_cameras && f.cameras_raw > 0 && f.floor_raw > 0 &&
                                2 * f.cameras_raw * f.cameras_raw > f.floor_raw * f.floor_raw;
  if (!cameras_dominate && d.principal_point_from_depth_image) {
    Say(d, "Nothing to add that this session can tell from the cameras: " + floor_text +
               ". The depth camera's principal point was fitted to the depth image alone, so a shift of the depth "
               "image from the IR image (depth_grid_offset, 3-4 px on stock Kinects) is in its cx and cy, not in "
               "the model, and the held-out depths reach the floor with it there. An IR chessboard recording "
               "(record-session freenect "
               "--purpose ir_chessboard --add-to SESSION) would tell the two apart.");
    return;
  }
  if (!cameras_dominate) {
    Say(d, "The model is complete: " + floor_text + ". Nothing to add.");
    return;
  }
  Say(d,
      fmt::format("The model is as good as the cameras allow: {}. Most of that floor ({:.3f} of {:.3f} {u}) is the "
                  "cameras' calibration uncertainty, so an effect smaller than it cannot be seen. Nothing to add; an "
                  "IR chessboard recording or more chessboard views (tilted, near the image corners) would narrow "
                  "the cameras and let the diagnosis see further.",
                  floor_text, f.cameras_raw, f.floor_raw, fmt::arg("u", d.reading_unit)));
}

}  // namespace

const char* ConclusionName(Conclusion c) {
  switch (c) {
    case Conclusion::kComplete:
      return "complete";
    case Conclusion::kAddEffect:
      return "add_effect";
    case Conclusion::kMorePoses:
      return "record_more_poses";
    case Conclusion::kRecalibrateCameras:
      return "recalibrate_cameras";
    case Conclusion::kOutsideCatalogue:
      return "outside_catalogue";
  }
  return "unknown";
}

void ConcludeDiagnosis(const DiagnosisOptions& options, Diagnosis& d) {
  DescribeTest(options, d);
  d.verdict.clear();
  d.borderline.clear();
  const std::string floor_text =
      d.judged_jointly
          ? fmt::format(
                "held-out RMS {:.3f} {u} ({:.2f} mm), each pose predicted by a joint calibration that never saw "
                "its depths, against a noise floor of {:.3f} {u} ({}; ratio {:.2f})",
                d.held_out_rms, d.held_out_mm, d.floor.floor_raw, d.floor.source, d.ratio_to_floor,
                fmt::arg("u", d.reading_unit))
      : d.judged_beyond_cameras
          ? fmt::format(
                "held-out RMS {:.3f} {u} ({:.2f} mm), {:.3f} {u} with the cameras free within their "
                "uncertainty, against a noise floor beyond the cameras of {:.3f} {u} ({}; ratio {:.2f})",
                d.held_out_rms, d.held_out_mm, *d.cameras_free_held_out_rms, d.floor.beyond_cameras_raw, d.floor.source,
                d.ratio_to_floor, fmt::arg("u", d.reading_unit))
          : fmt::format("held-out RMS {:.3f} {u} ({:.2f} mm) against a noise floor of {:.3f} {u} ({}; ratio {:.2f})",
                        d.held_out_rms, d.held_out_mm, d.floor.floor_raw, d.floor.source, d.ratio_to_floor,
                        fmt::arg("u", d.reading_unit));
  if (d.complete) {
    d.conclusion = Conclusion::kComplete;
    SayComplete(floor_text, d);
    return;
  }
  bool cameras_explain = false;
  const Candidate* chosen = Recommend(options, d, cameras_explain);
  const CovariateFinding* named = NamedFinding(options, d, chosen);
  if (named) d.named_covariate = named->covariate;
  const std::string where = WhereText(options, d, named);
  d.formula_hint = FormulaFor(named                  ? named->covariate
                              : d.covariates.empty() ? "raw"
                                                     : d.covariates.front().covariate,
                              d);
  if (chosen) {
    SayRecommended(options, where, *chosen, d);
  } else if (d.coverage.under_determined) {
    SayMorePoses(where, floor_text, d);
  } else if (cameras_explain && d.cameras_free_held_out_rms) {
    SayCameras(where, floor_text, d);
  } else {
    d.conclusion = Conclusion::kOutsideCatalogue;
    Say(d, fmt::format("{}; {}. No catalogue effect passes the pose-level test; ", where, floor_text));
    if (!named) {
      // The formula then follows the strongest covariate, however weak: a
      // lead to try, not a finding.
      Say(d, "no covariate points to what is missing either, so any formula is a guess; to try one, ");
    }
    SuggestFormula(d);
  }
  SayBorderline(options, d);
}

bool RecommendedLeavesExcess(const DiagnosisOptions& options, const Diagnosis& d) {
  if (!d.recommended) return false;
  const auto c = std::find_if(d.candidates.begin(), d.candidates.end(), [](const auto& c) { return c.recommended; });
  const double floor = d.floor.floor_raw;
  return c != d.candidates.end() && floor > 0 && c->held_out_rms > options.complete_ratio * floor;
}

void DescribePair(const DiagnosisOptions& options, Diagnosis& d) {
  if (!RecommendedLeavesExcess(options, d)) return;
  const auto c = std::find_if(d.candidates.begin(), d.candidates.end(), [](const auto& c) { return c.recommended; });
  const double floor = d.floor.floor_raw;
  if (!d.best_pair) {
    Say(d, ". No second catalogue effect could be tried with it");
    return;
  }
  const PairFinding& p = *d.best_pair;
  const bool helps = options.PassesPoseTest(p.reduction_over_single, p.p_value);
  const double left = p.held_out_rms / floor;
  if (helps) {
    Say(d, fmt::format(". With {} as well the held-out RMS comes to {:.3f} {u} ({:.2f} times the floor; {} % below {} "
                       "alone, better on {} of {} poses, {}): run ",
                       p.second, p.held_out_rms, left, std::lround(100 * p.reduction_over_single), c->name,
                       p.poses_better, p.poses_compared, PText(p.p_value), fmt::arg("u", d.reading_unit)));
    d.verdict.push_back({VerdictPart::Kind::kAddEffect, c->name + " " + p.second});
    if (left > options.complete_ratio) Say(d, "; what remains after both has no catalogue effect");
  } else {
    Say(d, fmt::format(". No second catalogue effect helps on top of it (the best, {}, {:+.0f} %, {}): what remains "
                       "is outside the catalogue",
                       p.second, -100 * p.reduction_over_single, PText(p.p_value)));
  }
}

void SayJointDeclined(Diagnosis& d) {
  if (d.joint_declined.empty()) return;
  const bool after_sentence = !d.verdict.empty() && d.verdict.back().kind == VerdictPart::Kind::kWords &&
                              !d.verdict.back().argument.empty() && d.verdict.back().argument.back() == '.';
  Say(d, fmt::format("{}Not judged in the joint calibration: {}. The current model and the candidates were held out "
                     "in the depth fit with the cameras held instead.",
                     after_sentence ? " " : ". ", d.joint_declined));
}

}  // namespace speckle
