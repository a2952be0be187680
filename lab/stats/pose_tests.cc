#include "lab/stats/pose_tests.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <random>

namespace speckle {
namespace {

// P(positive rank sum >= w) under independent fair sign flips of ranks given
// as whole half-units (twice the rank, so mean ranks of ties stay integer).
double UpperTail(const std::vector<int>& doubled_ranks, int doubled_w) {
  const int total = std::accumulate(doubled_ranks.begin(), doubled_ranks.end(), 0);
  std::vector<double> p(static_cast<std::size_t>(total) + 1, 0.0);
  p[0] = 1;
  int reach = 0;
  for (int r : doubled_ranks) {
    for (int s = reach; s >= 0; --s) {
      const double half = p[static_cast<std::size_t>(s)] * 0.5;
      p[static_cast<std::size_t>(s)] = half;
      p[static_cast<std::size_t>(s + r)] += half;
    }
    reach += r;
  }
  double tail = 0;
  for (int s = std::max(0, doubled_w); s <= total; ++s) tail += p[static_cast<std::size_t>(s)];
  return std::min(1.0, tail);
}

}  // namespace

double SignedRankPValue(const std::vector<double>& differences) {
  std::vector<double> d;
  for (double v : differences)
    if (std::isfinite(v) && v != 0) d.push_back(v);
  if (d.empty()) return 1;
  std::vector<std::size_t> order(d.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return std::abs(d[a]) < std::abs(d[b]); });
  std::vector<int> doubled(d.size());
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i;
    while (j + 1 < order.size() && std::abs(d[order[j + 1]]) == std::abs(d[order[i]])) ++j;
    // Ranks i+1 .. j+1 share their mean, (i + j + 2) / 2; doubled: i + j + 2.
    for (std::size_t k = i; k <= j; ++k) doubled[order[k]] = static_cast<int>(i + j + 2);
    i = j + 1;
  }
  int positive = 0;
  for (std::size_t i = 0; i < d.size(); ++i)
    if (d[i] > 0) positive += doubled[i];
  return UpperTail(doubled, positive);
}

int PosesNeededToGain(int n, double p_max) {
  for (int k = 1; k <= n; ++k) {
    std::vector<double> d;
    for (int i = 1; i <= n; ++i) d.push_back(i > n - k ? i : -i);
    if (SignedRankPValue(d) <= p_max) return k;
  }
  return n + 1;
}

namespace {

// Each pose's value predicted by the mean of the other poses in its group of
// covariate neighbours (groups by rank of the covariate).
std::vector<double> HeldOutProfile(const std::vector<std::size_t>& by_covariate, const std::vector<double>& value,
                                   int bins) {
  const std::size_t n = by_covariate.size();
  std::vector<double> prediction(n, 0.0);
  for (int b = 0; b < bins; ++b) {
    const std::size_t lo = n * static_cast<std::size_t>(b) / static_cast<std::size_t>(bins);
    const std::size_t hi = n * static_cast<std::size_t>(b + 1) / static_cast<std::size_t>(bins);
    if (hi - lo < 2) continue;  // a lone pose predicts nothing about itself
    double sum = 0;
    for (std::size_t k = lo; k < hi; ++k) sum += value[by_covariate[k]];
    for (std::size_t k = lo; k < hi; ++k)
      prediction[by_covariate[k]] = (sum - value[by_covariate[k]]) / static_cast<double>(hi - lo - 1);
  }
  return prediction;
}

// The squares the step with a common slope that best fits the poses (in
// covariate order) explains, the split searched with at least 3 poses a side.
double BestStepExplained(const std::vector<double>& x, const std::vector<double>& y) {
  const std::size_t n = x.size();
  constexpr std::size_t kMinSide = 3;
  struct Sums {
    double n = 0, x = 0, xx = 0, y = 0, xy = 0;
    void Add(double xi, double yi, double s) { n += s, x += s * xi, xx += s * xi * xi, y += s * yi, xy += s * xi * yi; }
  } below, above;
  for (std::size_t k = 0; k < n; ++k) above.Add(x[k], y[k], 1);
  double best = 0;
  for (std::size_t k = 0; k + kMinSide < n; ++k) {
    below.Add(x[k], y[k], 1), above.Add(x[k], y[k], -1);
    if (k + 1 < kMinSide) continue;
    double sxx = 0, sxy = 0, explained = 0;
    for (const Sums* g : {&below, &above}) {
      sxx += g->xx - g->x * g->x / g->n, sxy += g->xy - g->x * g->y / g->n;
      explained += g->y * g->y / g->n;
    }
    best = std::max(best, explained + (sxx > 0 ? sxy * sxy / sxx : 0));
  }
  return best;
}

double Gain(const std::vector<double>& value, const std::vector<double>& prediction) {
  double g = 0;
  for (std::size_t i = 0; i < value.size(); ++i) g += value[i] * value[i] - std::pow(value[i] - prediction[i], 2);
  return g;
}

}  // namespace

ProfileTest PoseProfileTest(const std::vector<double>& covariate, const std::vector<double>& value, int bins,
                            int permutations, std::uint64_t seed) {
  ProfileTest t;
  const std::size_t n = value.size();
  t.prediction.assign(n, 0.0);
  if (n < 6 || covariate.size() != n) return t;
  bins = std::clamp(bins, 2, static_cast<int>(n / 3));
  std::vector<std::size_t> by_covariate(n);
  std::iota(by_covariate.begin(), by_covariate.end(), 0);
  std::stable_sort(by_covariate.begin(), by_covariate.end(),
                   [&](std::size_t a, std::size_t b) { return covariate[a] < covariate[b]; });
  t.prediction = HeldOutProfile(by_covariate, value, bins);
  t.gain = Gain(value, t.prediction);
  std::mt19937_64 rng(seed);
  std::vector<double> shuffled = value;
  int at_least = 0;
  for (int k = 0; k < permutations; ++k) {
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    // Reorderings within a group give the same statistic summed in another
    // order: count such ties as ties, whatever the last bits say.
    if (Gain(shuffled, HeldOutProfile(by_covariate, shuffled, bins)) >= t.gain - 1e-9 * std::abs(t.gain)) ++at_least;
  }
  t.p_value = (at_least + 1.0) / (permutations + 1.0);
  return t;
}

ProfileTest PoseStepTest(const std::vector<double>& covariate, const std::vector<double>& value, int permutations,
                         std::uint64_t seed) {
  ProfileTest t;
  const std::size_t n = value.size();
  t.prediction.assign(n, 0.0);
  if (n < 8 || covariate.size() != n) return t;
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return covariate[a] < covariate[b]; });
  std::vector<double> x(n), y(n);
  for (std::size_t k = 0; k < n; ++k) x[k] = covariate[order[k]], y[k] = value[order[k]];
  t.gain = BestStepExplained(x, y);
  std::mt19937_64 rng(seed);
  int at_least = 0;
  for (int k = 0; k < permutations; ++k) {
    std::shuffle(y.begin(), y.end(), rng);
    const double gain = BestStepExplained(x, y);
    t.chance_gain += gain / permutations;
    if (gain >= t.gain - 1e-9 * std::abs(t.gain)) ++at_least;
  }
  t.p_value = (at_least + 1.0) / (permutations + 1.0);
  return t;
}

// Mean gain per pose over its standard error.
double MeanGainSignificance(const std::map<int, double>& gain_by_pose) {
  const double n = static_cast<double>(gain_by_pose.size());
  if (n < 3) return 0;
  double mean = 0, sq = 0;
  for (const auto& [pose, g] : gain_by_pose) mean += g / n;
  for (const auto& [pose, g] : gain_by_pose) sq += (g - mean) * (g - mean);
  const double se = std::sqrt(sq / (n - 1) / n);
  return se > 0 ? mean / se : 0;
}

ReductionInterval PoseBootstrapReduction(const std::vector<std::pair<double, double>>& squares, int resamples,
                                         std::uint64_t seed) {
  if (squares.size() < 3 || resamples < 1) return {};
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, squares.size() - 1);
  std::vector<double> reductions;
  for (int r = 0; r < resamples; ++r) {
    double without = 0, with = 0;
    for (std::size_t k = 0; k < squares.size(); ++k) {
      const auto& [a, b] = squares[pick(rng)];
      without += a, with += b;
    }
    if (without > 0) reductions.push_back(1 - std::sqrt(with / without));
  }
  if (reductions.empty()) return {};
  std::sort(reductions.begin(), reductions.end());
  const auto at = [&](double q) { return reductions[static_cast<std::size_t>(q * (reductions.size() - 1))]; };
  return {at(0.05), at(0.95)};
}

}  // namespace speckle
