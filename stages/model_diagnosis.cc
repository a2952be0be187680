#include "stages/model_diagnosis.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>

#include "model/effect.h"

namespace speckle {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

NoiseFloor EstimateFloor(const std::vector<PairedSample>& samples, const std::vector<double>& residual) {
  NoiseFloor floor;
  floor.quantization_raw = 1 / std::sqrt(12.0);
  // The same board point over the frames of one still pose: what differs is
  // noise (raw value and colour pose), never the model.
  std::map<std::pair<int, int>, std::vector<double>> groups;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (samples[i].board_point >= 0) groups[{samples[i].pose, samples[i].board_point}].push_back(residual[i]);
  }
  double squares = 0, dof = 0;
  for (const auto& [key, values] : groups) {
    if (values.size() < 2) continue;
    double mean = 0;
    for (double v : values) mean += v / static_cast<double>(values.size());
    for (double v : values) squares += (v - mean) * (v - mean);
    dof += static_cast<double>(values.size()) - 1;
    ++floor.repeated_groups;
  }
  if (floor.repeated_groups >= 30) floor.repeated_frames_raw = std::sqrt(squares / dof);
  // Neighbouring pixels of one frame (board-plane pixels): a smooth model
  // error cancels in their difference; spatially correlated noise partly does
  // too, so this floor is a lower bound.
  std::map<std::tuple<int, int, int>, double> by_pixel;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (samples[i].point != SamplePoint::kBoardPlanePixel) continue;
    by_pixel[{samples[i].frame, static_cast<int>(std::lround(samples[i].v)), static_cast<int>(std::lround(samples[i].u))}] = residual[i];
  }
  double pair_squares = 0;
  int pairs = 0;
  // Board-plane pixels may be a sparse subset: the next one along the row within 3 pixels.
  for (auto it = by_pixel.begin(); it != by_pixel.end(); ++it) {
    const auto next = std::next(it);
    if (next == by_pixel.end()) break;
    const auto [frame, v, u] = it->first;
    const auto [next_frame, next_v, next_u] = next->first;
    if (next_frame == frame && next_v == v && next_u - u <= 3)
      pair_squares += (it->second - next->second) * (it->second - next->second), ++pairs;
  }
  if (pairs >= 100) floor.neighbour_pixels_raw = std::sqrt(pair_squares / pairs / 2);
  if (floor.repeated_frames_raw > 0) {
    floor.floor_raw = floor.repeated_frames_raw;
    floor.source = "repeated frames of still board poses";
  } else if (floor.neighbour_pixels_raw > 0) {
    floor.floor_raw = floor.neighbour_pixels_raw;
    floor.source = "neighbouring pixels of each frame";
  } else {
    floor.floor_raw = floor.quantization_raw;
    floor.source = "quantization only (no repeated frames)";
  }
  return floor;
}

struct CovariateAxis {
  const char* name;
  const char* unit;
  std::function<double(const PairedSample&)> value;
  std::function<double(const PairedSample&)> second;  // set for 2-D axes
};

const std::vector<CovariateAxis>& Axes() {
  static const std::vector<CovariateAxis> axes = {
      {"raw", "raw", [](const PairedSample& s) { return s.raw; }, nullptr},
      {"depth", "m", [](const PairedSample& s) { return s.depth_m; }, nullptr},
      {"image radius", "1", [](const PairedSample& s) { return std::hypot(s.x, s.y); }, nullptr},
      {"image x", "1", [](const PairedSample& s) { return s.x; }, nullptr},
      {"image y", "1", [](const PairedSample& s) { return s.y; }, nullptr},
      {"image position", "px", [](const PairedSample& s) { return s.u; }, [](const PairedSample& s) { return s.v; }},
      {"time", "s", [](const PairedSample& s) { return s.time_s; }, nullptr},
      {"board tilt", "deg", [](const PairedSample& s) { return s.tilt_deg; }, nullptr},
      {"depth gradient", "raw/px",
       [](const PairedSample& s) { return std::hypot(s.gradient_u, s.gradient_v); }, nullptr},
      {"gradient along u", "raw/px", [](const PairedSample& s) { return s.gradient_u; }, nullptr},
      {"gradient along v", "raw/px", [](const PairedSample& s) { return s.gradient_v; }, nullptr},
      {"raw change with motion", "raw/s",
       [](const PairedSample& s) { return s.gradient_u * s.velocity_u + s.gradient_v * s.velocity_v; }, nullptr},
      {"albedo", "1", [](const PairedSample& s) { return s.albedo; }, nullptr},
  };
  return axes;
}

// Bin index per sample: quantile bins of one axis, or a grid over two.
std::vector<int> Bins(const CovariateAxis& axis, const std::vector<PairedSample>& samples, int bins, int& count) {
  const auto edges = [&](const std::function<double(const PairedSample&)>& f, int n) {
    std::vector<double> values;
    for (const auto& s : samples) values.push_back(f(s));
    std::sort(values.begin(), values.end());
    std::vector<double> e;
    for (int k = 1; k < n; ++k) e.push_back(values[values.size() * static_cast<std::size_t>(k) / static_cast<std::size_t>(n)]);
    return e;
  };
  const auto locate = [](const std::vector<double>& e, double v) {
    return static_cast<int>(std::upper_bound(e.begin(), e.end(), v) - e.begin());
  };
  std::vector<int> bin;
  if (axis.second) {
    const int n = std::max(2, bins / 2);
    const auto eu = edges(axis.value, n), ev = edges(axis.second, n);
    for (const auto& s : samples) bin.push_back(locate(ev, axis.second(s)) * n + locate(eu, axis.value(s)));
    count = n * n;
  } else {
    const auto e = edges(axis.value, bins);
    for (const auto& s : samples) bin.push_back(locate(e, axis.value(s)));
    count = bins;
  }
  return bin;
}

// Mean gain per pose over its standard error.
double Significance(const std::map<int, double>& gain_by_pose) {
  const double n = static_cast<double>(gain_by_pose.size());
  if (n < 3) return 0;
  double mean = 0, sq = 0;
  for (const auto& [pose, g] : gain_by_pose) mean += g / n;
  for (const auto& [pose, g] : gain_by_pose) sq += (g - mean) * (g - mean);
  const double se = std::sqrt(sq / (n - 1) / n);
  return se > 0 ? mean / se : 0;
}

CovariateFinding Analyse(const CovariateAxis& axis, const std::vector<PairedSample>& samples,
                         const std::vector<double>& residual, const std::vector<int>& fold, int folds, int bins,
                         double excess) {
  CovariateFinding finding{axis.name, axis.unit};
  int count = 0;
  const std::vector<int> bin = Bins(axis, samples, bins, count);
  // Bin means from the other folds predict each fold's residuals.
  std::vector<std::vector<double>> sum(static_cast<std::size_t>(folds), std::vector<double>(count, 0.0));
  std::vector<std::vector<double>> n(static_cast<std::size_t>(folds), std::vector<double>(count, 0.0));
  std::vector<double> total_sum(count, 0.0), total_n(count, 0.0), centre(count, 0.0);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!std::isfinite(residual[i])) continue;
    sum[fold[i]][bin[i]] += residual[i], n[fold[i]][bin[i]] += 1;
    total_sum[bin[i]] += residual[i], total_n[bin[i]] += 1;
    centre[bin[i]] += axis.value(samples[i]);
  }
  std::map<int, double> gain_by_pose;
  double explained = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!std::isfinite(residual[i])) continue;
    const int b = bin[i];
    const double others = total_n[b] - n[fold[i]][b];
    const double prediction = others > 0 ? (total_sum[b] - sum[fold[i]][b]) / others : 0;
    const double gain = residual[i] * residual[i] - (residual[i] - prediction) * (residual[i] - prediction);
    gain_by_pose[samples[i].pose] += gain;
    explained += gain;
  }
  finding.explained_share = excess > 0 ? std::clamp(explained / excess, 0.0, 1.0) : 0;
  finding.significance = Significance(gain_by_pose);
  if (!axis.second) {
    for (int b = 0; b < count; ++b) {
      if (total_n[b] == 0) continue;
      finding.bin_centre.push_back(centre[b] / total_n[b]);
      finding.bin_mean.push_back(total_sum[b] / total_n[b]);
      finding.bin_count.push_back(total_n[b]);
    }
  }
  return finding;
}

std::vector<std::pair<std::string, model::ModelDefinition>> CandidateModels(const model::ModelDefinition& current) {
  std::vector<std::pair<std::string, model::ModelDefinition>> out;
  for (const auto& info : model::EffectCatalogue()) {
    bool present = false;
    for (const auto& e : current.effects) present = present || e.name == info.name;
    if (present) continue;
    model::ModelDefinition d = current;
    d.effects.push_back({info.name});
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

std::string Doc(const std::string& name) {
  for (const auto& info : model::EffectCatalogue())
    if (info.name == name) return info.doc;
  if (name.rfind("base_form:", 0) == 0) return "another base form for the raw-to-depth relation";
  return "";
}

}  // namespace

Diagnosis RunModelDiagnosis(const DiagnosisOptions& options, const std::vector<PairedSample>& samples,
                            const DepthFit& fit, const std::string& session) {
  Diagnosis d;
  d.floor = EstimateFloor(samples, fit.residual_raw);
  d.held_out_rms = fit.held_out_raw.rms;
  d.held_out_mm = fit.held_out_mm.rms;
  d.ratio_to_floor = d.floor.floor_raw > 0 ? d.held_out_rms / d.floor.floor_raw : 0;
  d.complete = d.ratio_to_floor <= options.complete_ratio;

  const std::vector<int> fold = FoldsByPose(samples, options.folds);
  const int folds = fold.empty() ? 1 : *std::max_element(fold.begin(), fold.end()) + 1;
  double squares = 0, finite = 0;
  for (double r : fit.held_out_residual_raw)
    if (std::isfinite(r)) squares += r * r, finite += 1;
  const double excess = squares - finite * d.floor.floor_raw * d.floor.floor_raw;
  for (const auto& axis : Axes())
    d.covariates.push_back(Analyse(axis, samples, fit.held_out_residual_raw, fold, folds, options.bins, excess));
  std::sort(d.covariates.begin(), d.covariates.end(),
            [](const auto& a, const auto& b) { return a.explained_share > b.explained_share; });

  // Every candidate on its own, fitted and held out by pose on an even subsample.
  std::vector<std::size_t> chosen;
  const std::size_t stride = std::max<std::size_t>(1, (samples.size() + options.max_candidate_samples - 1) / options.max_candidate_samples);
  for (std::size_t i = 0; i < samples.size(); i += stride) chosen.push_back(i);
  std::vector<PairedSample> subset;
  for (std::size_t i : chosen) subset.push_back(samples[i]);
  const auto models = CandidateModels(fit.definition);
  d.candidates.resize(models.size());
  DepthFitOptions fit_options;
  fit_options.folds = options.folds;
  fit_options.max_iterations = 30;  // a ranking needs the error to a few per cent, not the last digit
  tbb::parallel_for(std::size_t{0}, models.size(), [&](std::size_t k) {
    Candidate& c = d.candidates[k];
    c.name = models[k].first;
    c.doc = Doc(c.name);
    const auto result = RunDepthModelFit(fit_options, models[k].second, subset);
    if (!Accepted(result)) return;
    const DepthFit& candidate = std::get<DepthFit>(result);
    std::map<int, double> gain_by_pose;
    double current = 0, next = 0, n = 0;
    for (std::size_t j = 0; j < chosen.size(); ++j) {
      const double a = fit.held_out_residual_raw[chosen[j]], b = candidate.held_out_residual_raw[j];
      if (!std::isfinite(a) || !std::isfinite(b)) continue;
      current += a * a, next += b * b, n += 1;
      gain_by_pose[subset[j].pose] += a * a - b * b;
    }
    if (n == 0) return;
    c.held_out_rms = std::sqrt(next / n);
    c.held_out_mm = candidate.held_out_mm.rms;
    c.reduction = 1 - std::sqrt(next / current);
    c.significance = Significance(gain_by_pose);
  });
  std::sort(d.candidates.begin(), d.candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.reduction > b.reduction; });

  const auto percent = [](double share) { return fmt::format("{:.0f} %", 100 * share); };
  const CovariateFinding* top = d.covariates.empty() ? nullptr : &d.covariates.front();
  const std::string floor_text = fmt::format("held-out RMS {:.3f} raw ({:.2f} mm) against a noise floor of {:.3f} raw "
                                             "({}; ratio {:.2f})",
                                             d.held_out_rms, d.held_out_mm, d.floor.floor_raw, d.floor.source,
                                             d.ratio_to_floor);
  if (d.complete) {
    d.verdict = "The model is complete: " + floor_text + ". Nothing to add.";
    return d;
  }
  for (auto& c : d.candidates) {
    if (c.reduction >= options.min_reduction && c.significance >= options.min_significance) {
      c.recommended = true;
      d.recommended = c.name;
      break;
    }
  }
  const std::string where =
      top && top->significance >= options.min_significance
          ? fmt::format("residuals vary with {} ({} of the excess over the noise floor)", top->covariate,
                        percent(top->explained_share))
          : std::string("residuals exceed the noise floor without a clear covariate");
  const std::string variable = top ? top->covariate : "a covariate";
  const std::string formula_hint = fmt::format(
      "write an effect for it as a formula in the model spec, e.g. {{\"name\": \"my_effect\", \"formula\": "
      "\"k * (raw - 700)\", \"parameters\": [{{\"name\": \"k\", \"unit\": \"1\"}}]}} over the variables of {} "
      "(see examples/hunt/README.md), then: refit {} --model MODEL.json",
      variable, session);
  if (d.recommended) {
    const Candidate& c = *std::find_if(d.candidates.begin(), d.candidates.end(), [](const auto& c) { return c.recommended; });
    const bool base = c.name.rfind("base_form:", 0) == 0;
    d.verdict = fmt::format("{}; adding {} cuts held-out RMS from {:.3f} raw ({:.2f} mm) to {:.3f} raw ({:.2f} mm) — "
                            "run: {}",
                            where, c.name, d.held_out_rms, d.held_out_mm, c.held_out_rms, c.held_out_mm,
                            base ? fmt::format("refit {} --model MODEL.json with \"base_form\": \"{}\"", session, c.name.substr(10))
                                 : fmt::format("refit {} --add-effect {}", session, c.name));
    const double left = d.floor.floor_raw > 0 ? c.held_out_rms / d.floor.floor_raw : 0;
    if (left > options.complete_ratio) {
      d.verdict += fmt::format(". It explains only part: with it the error stays {:.2f} times the noise floor. If the "
                               "next verdict finds nothing more, {}",
                               left, formula_hint);
    }
  } else {
    d.verdict = fmt::format("{}; {}. No catalogue effect explains it; {}", where, floor_text, formula_hint);
  }
  return d;
}

}  // namespace speckle
