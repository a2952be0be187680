#include "pipeline/refit_costs.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "lab/fit/depth_uncertainty.h"

namespace speckle {
namespace {

// A sigma that grows by more than this share is called out: less than it is
// within what the error bars' own estimate moves between refits.
constexpr double kGrowthCalledOut = 0.2;

// The parent's sigma at `depth_m`, linear between its rows; none outside them.
std::optional<double> ParentSigmaMm(const nlohmann::json& rows, double depth_m) {
  std::vector<std::pair<double, double>> at;
  for (const auto& r : rows)
    if (r.is_object() && r.value("depth_m", nlohmann::json()).is_number() &&
        r.value("sigma_mm", nlohmann::json()).is_number())
      at.emplace_back(r["depth_m"].get<double>(), r["sigma_mm"].get<double>());
  std::sort(at.begin(), at.end());
  for (std::size_t i = 1; i < at.size(); ++i) {
    const auto [z0, s0] = at[i - 1];
    const auto [z1, s1] = at[i];
    if (depth_m < z0 || depth_m > z1 || !(z1 > z0)) continue;
    return s0 + (s1 - s0) * (depth_m - z0) / (z1 - z0);
  }
  return std::nullopt;
}

std::string AgainstParentSigma(const nlohmann::json& rows, const std::string& parent_name,
                               const std::vector<DepthSigma>& now) {
  const DepthSigma* worst = nullptr;
  double worst_ratio = 0, worst_before = 0;
  for (const DepthSigma& r : now) {
    const auto before = ParentSigmaMm(rows, r.depth_m);
    if (!before || !(*before > 0)) continue;
    if (r.sigma_mm / *before > worst_ratio) worst = &r, worst_ratio = r.sigma_mm / *before, worst_before = *before;
  }
  if (!worst) return {};
  if (worst_ratio - 1 <= kGrowthCalledOut)
    return fmt::format("             against {}: within {:.0f} % of its sigma at every depth (largest {:+.0f} %)\n",
                       parent_name, 100 * kGrowthCalledOut, std::round(100 * (worst_ratio - 1)) + 0.0);
  return fmt::format(
      "             against {}: the sigma grows, most at {:.2f} m{}: ± {:.1f} -> ± {:.1f} mm ({:+.0f} %); the new "
      "parameters are known less well than the old, so every depth carries a wider error bar\n",
      parent_name, worst->depth_m, worst->extrapolated ? " (extrapolated)" : "", worst_before, worst->sigma_mm,
      100 * (worst_ratio - 1));
}

}  // namespace

std::string RefitCosts(const nlohmann::json& parent_report, const std::string& parent_name, const ModelLab& lab,
                       const CameraCalibration& cameras) {
  const std::vector<DepthSigma> rows = DepthUncertainty(lab.Chosen(), lab.ChosenSamples());
  std::string out = DepthUncertaintyLine(rows, cameras);
  out += AgainstParentSigma(parent_report.value("depth_uncertainty", nlohmann::json::array()), parent_name, rows);
  if (!cameras.depth_intrinsics_warning.empty())
    out += fmt::format("warning      {}\n", cameras.depth_intrinsics_warning);
  return out;
}

}  // namespace speckle
