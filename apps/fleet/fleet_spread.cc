#include "apps/fleet/fleet_spread.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

namespace speckle::fleet {
namespace {

// P(|T| > t). With x = sqrt(dof) tan(u) the density is a constant times
// cos(u)^(dof - 1) on [0, pi/2): smooth, so Simpson's rule is exact to far
// below the tails asked for.
double TwoSidedTail(double t, double dof) {
  const double norm = std::exp(std::lgamma((dof + 1) / 2) - std::lgamma(dof / 2)) / std::sqrt(M_PI);
  const double end = std::atan(t / std::sqrt(dof));
  constexpr int kSteps = 2000;
  const double h = end / kSteps;
  const auto f = [&](double u) { return std::pow(std::cos(u), dof - 1); };
  double sum = f(0) + f(end);
  for (int i = 1; i < kSteps; ++i) sum += (i % 2 ? 4 : 2) * f(i * h);
  return 1 - 2 * norm * sum * h / 3;
}

}  // namespace

double StudentTQuantile(double alpha, double dof) {
  double low = 0, high = 1e6;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (low + high);
    (TwoSidedTail(mid, dof) > alpha ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

std::vector<OutOfSpread> FindOutOfSpread(const std::vector<UnitRecord>& units, const SpreadOptions& options) {
  std::map<std::string, std::vector<std::pair<const UnitRecord*, Parameter>>> by_name;
  std::size_t calibrated = 0;
  for (const auto& u : units) {
    if (!u.calibrated) continue;
    ++calibrated;
    for (const auto& p : u.parameters) by_name[p.name].push_back({&u, p});
  }
  std::erase_if(by_name, [&](const auto& entry) { return entry.second.size() != calibrated; });
  const double others = static_cast<double>(calibrated) - 1;
  if (others < options.min_other_units || by_name.empty()) return {};
  const double threshold =
      StudentTQuantile(options.fleet_false_alarm / (static_cast<double>(calibrated) * by_name.size()), others - 1);
  std::vector<OutOfSpread> out;
  for (const auto& [name, values] : by_name)
    for (std::size_t i = 0; i < values.size(); ++i) {
      double sum = 0, ss = 0, sigma_ss = 0;
      for (std::size_t k = 0; k < values.size(); ++k)
        if (k != i) sum += values[k].second.value, sigma_ss += std::pow(values[k].second.sigma, 2);
      const double mean = sum / others;
      for (std::size_t k = 0; k < values.size(); ++k)
        if (k != i) ss += std::pow(values[k].second.value - mean, 2);
      const double variance = ss / (others - 1), make_variance = std::max(0.0, variance - sigma_ss / others);
      const Parameter& p = values[i].second;
      const double scale = std::sqrt(variance / others + make_variance + p.sigma * p.sigma);
      const double z = scale > 0 ? (p.value - mean) / scale : 0;
      if (std::abs(z) > threshold)
        out.push_back({values[i].first->serial, name, p.value, mean, std::sqrt(make_variance), p.sigma, z, threshold});
    }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return std::abs(a.z) > std::abs(b.z); });
  return out;
}

}  // namespace speckle::fleet
