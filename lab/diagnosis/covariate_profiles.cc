#include "lab/diagnosis/covariate_profiles.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numeric>

#include "lab/diagnosis/covariate_axes.h"
#include "lab/stats/pose_tests.h"
#include "stages/significant_digits.h"

namespace speckle {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Whether an axis takes more than one value over the samples. One that does
// not (time in a toolbox's frame folder, which has no timestamps) explains
// nothing, and its profile's groups would follow the poses' order instead.
bool Varies(const CovariateAxis& axis, const std::vector<PairedSample>& samples) {
  const auto differs = [&](const std::function<double(const PairedSample&)>& value) {
    for (const auto& s : samples)
      if (std::isfinite(value(s)) && value(s) != value(samples.front())) return true;
    return false;
  };
  return !samples.empty() && (differs(axis.value) || (axis.second && differs(axis.second)));
}

// A covariate as binned: to 9 significant digits. Many samples share a value
// (gradients of integer raw values), and last-bit noise upstream would
// otherwise move some of them across an edge that is one of those values.
double Binned(double v) { return RoundToSignificantDigits(v, 9); }

// Bin index per sample: quantile bins of one axis, or a grid over two.
std::vector<int> Bins(const CovariateAxis& axis, const std::vector<PairedSample>& samples, int bins, int& count) {
  const auto edges = [&](const std::function<double(const PairedSample&)>& f, int n) {
    std::vector<double> values;
    for (const auto& s : samples) values.push_back(Binned(f(s)));
    std::sort(values.begin(), values.end());
    std::vector<double> e;
    for (int k = 1; k < n; ++k)
      e.push_back(values[values.size() * static_cast<std::size_t>(k) / static_cast<std::size_t>(n)]);
    return e;
  };
  const auto locate = [](const std::vector<double>& e, double v) {
    return static_cast<int>(std::upper_bound(e.begin(), e.end(), Binned(v)) - e.begin());
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

CovariateFinding Analyse(const CovariateAxis& axis, const std::vector<PairedSample>& samples,
                         const std::vector<double>& residual, const std::vector<int>& fold, int folds, int bins,
                         double excess) {
  CovariateFinding finding;
  finding.covariate = axis.name;
  finding.unit = axis.unit;
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
  finding.significance = MeanGainSignificance(gain_by_pose);
  std::vector<double> gains;
  for (const auto& [pose, g] : gain_by_pose) gains.push_back(g);
  finding.p_value = SignedRankPValue(gains);
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

struct PoseMeans {
  std::vector<double> residual, covariate, count;
};

PoseMeans MeansByPose(const CovariateAxis& axis, const std::vector<PairedSample>& samples,
                      const std::vector<double>& residual) {
  struct Sums {
    double residual = 0, covariate = 0, n = 0;
  };
  std::map<int, Sums> by_pose;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!std::isfinite(residual[i])) continue;
    Sums& p = by_pose[samples[i].pose];
    p.residual += residual[i], p.covariate += axis.value(samples[i]), p.n += 1;
  }
  PoseMeans m;
  for (const auto& [pose, p] : by_pose) {
    m.residual.push_back(p.residual / p.n);
    m.covariate.push_back(p.covariate / p.n);
    m.count.push_back(p.n);
  }
  return m;
}

// Each pose's mean held-out residual against its mean covariate, tested over
// poses (lab/stats/pose_tests.h) at `p_value`; `explained` is the test's share
// of the squares counted over samples. The profile shows the poses
// themselves, by covariate (few enough to show).
CovariateFinding PoseLevelFinding(const CovariateAxis& axis, const PoseMeans& m, const std::string& level,
                                  double p_value, double explained, double excess) {
  CovariateFinding finding;
  finding.covariate = axis.name;
  finding.unit = axis.unit;
  finding.level = level;
  finding.explained_share = excess > 0 ? std::clamp(explained / excess, 0.0, 1.0) : 0;
  finding.p_value = p_value;
  finding.significance = kNaN;  // this level has only its permutation test
  std::vector<std::size_t> order(m.residual.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return m.covariate[a] < m.covariate[b]; });
  for (std::size_t k : order) {
    finding.bin_centre.push_back(m.covariate[k]);
    finding.bin_mean.push_back(m.residual[k]);
    finding.bin_count.push_back(m.count[k]);
  }
  return finding;
}

// The raw level where a step best fits the held-out residuals against the
// raw value, together with a common slope (the base form, refitted with the
// step, takes up the slope a fit without it leaves around the step). Prefix
// sums over the samples sorted by raw; levels between the 5th and 95th
// percentile: where a firmware-table seam would sit.
double BestStepLevel(const std::vector<PairedSample>& samples, const std::vector<double>& residual) {
  std::vector<std::pair<double, double>> by_raw;
  for (std::size_t i = 0; i < samples.size(); ++i)
    if (std::isfinite(residual[i])) by_raw.emplace_back(samples[i].raw, residual[i]);
  if (by_raw.size() < 20) return kNaN;
  std::sort(by_raw.begin(), by_raw.end());
  struct Sums {
    double n = 0, x = 0, xx = 0, r = 0, xr = 0;
    void Add(double xi, double ri, double sign) {
      n += sign, x += sign * xi, xx += sign * xi * xi, r += sign * ri, xr += sign * xi * ri;
    }
  };
  const double x0 = by_raw[by_raw.size() / 2].first;  // centred: sums of squares stay well conditioned
  Sums below, above;
  for (const auto& [raw, r] : by_raw) above.Add(raw - x0, r, 1);
  double best = -1, level = kNaN;
  for (std::size_t k = 0; k + 1 < by_raw.size(); ++k) {
    below.Add(by_raw[k].first - x0, by_raw[k].second, 1);
    above.Add(by_raw[k].first - x0, by_raw[k].second, -1);
    if (k < by_raw.size() / 20 || k > by_raw.size() * 19 / 20 || by_raw[k + 1].first == by_raw[k].first) continue;
    // Two intercepts and one slope: explained = sum n_g mean_g^2 + Sxr_within^2 / Sxx_within.
    double explained = 0, sxx = 0, sxr = 0;
    for (const Sums* g : {&below, &above}) {
      explained += g->r * g->r / g->n;
      sxx += g->xx - g->x * g->x / g->n;
      sxr += g->xr - g->x * g->r / g->n;
    }
    if (sxx > 0) explained += sxr * sxr / sxx;
    if (explained > best) best = explained, level = 0.5 * (by_raw[k].first + by_raw[k + 1].first);
  }
  return level;
}

}  // namespace

void ProfileCovariates(const DiagnosisOptions& options, const std::vector<PairedSample>& samples, const DepthFit& fit,
                       Diagnosis& d) {
  const std::vector<int> fold = FoldsByPose(samples, options.folds);
  const int folds = fold.empty() ? 1 : *std::max_element(fold.begin(), fold.end()) + 1;
  double squares = 0, finite = 0;
  for (double r : fit.held_out_residual_raw)
    if (std::isfinite(r)) squares += r * r, finite += 1;
  const double excess = squares - finite * d.floor.floor_raw * d.floor.floor_raw;
  for (const auto& axis : CovariateAxes()) {
    if (!Varies(axis, samples)) continue;
    d.covariates.push_back(Analyse(axis, samples, fit.held_out_residual_raw, fold, folds, options.bins, excess));
    if (!axis.pose_level) continue;  // a pose mostly has one value of it: one offset per pose
    const PoseMeans means = MeansByPose(axis, samples, fit.held_out_residual_raw);
    const ProfileTest profile = PoseProfileTest(means.covariate, means.residual, options.pose_profile_bins);
    double held_out = 0;  // each pose's samples at its held-out profile value
    for (std::size_t k = 0; k < means.residual.size(); ++k)
      held_out +=
          means.count[k] * (std::pow(means.residual[k], 2) - std::pow(means.residual[k] - profile.prediction[k], 2));
    d.covariates.push_back(PoseLevelFinding(axis, means, "pose means", profile.p_value, held_out, excess));
    // A step in the raw value (depth orders the poses alike): the profile's
    // groups of neighbouring poses straddle it. Its share is what it explains
    // beyond chance, each pose counting its mean number of samples.
    if (std::string(axis.name) == "raw") {
      const ProfileTest step = PoseStepTest(means.covariate, means.residual);
      const double per_pose = std::accumulate(means.count.begin(), means.count.end(), 0.0) /
                              static_cast<double>(std::max<std::size_t>(1, means.count.size()));
      d.covariates.push_back(PoseLevelFinding(axis, means, "pose means, step", step.p_value,
                                              per_pose * (step.gain - step.chance_gain), excess));
    }
  }
  std::sort(d.covariates.begin(), d.covariates.end(),
            [](const auto& a, const auto& b) { return a.explained_share > b.explained_share; });
  d.step_level_raw = BestStepLevel(samples, fit.held_out_residual_raw);
}

}  // namespace speckle
