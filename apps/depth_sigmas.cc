#include "apps/depth_sigmas.h"

#include <algorithm>
#include <cmath>

#include "schemas/artifact_schema.h"

namespace speckle {

apply::DepthSigmaTable DepthSigmasOf(const std::filesystem::path& calibration_file) {
  const auto report = calibration_file.parent_path() / "report.json";
  apply::DepthSigmaTable table;
  if (!std::filesystem::exists(report)) return table;
  const nlohmann::json j = ReadArtifactJson(report, "speckle.report", kReportSchemaVersion, 2);
  std::vector<std::pair<double, double>> rows;
  for (const auto& row : j.value("depth_uncertainty", nlohmann::json::array())) {
    const double depth = row.value("depth_m", 0.0), sigma_mm = row.value("sigma_mm", 0.0);
    if (std::isfinite(depth) && std::isfinite(sigma_mm) && depth > 0 && sigma_mm > 0)
      rows.emplace_back(depth, 1e-3 * sigma_mm);
  }
  std::sort(rows.begin(), rows.end());
  for (const auto& [depth, sigma] : rows) table.depth_m.push_back(depth), table.sigma_m.push_back(sigma);
  return table;
}

}  // namespace speckle
