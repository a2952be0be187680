#include "apps/depth_sigmas.h"

#include <algorithm>
#include <cmath>

#include "schemas/artifact_schema.h"
#include "schemas/calibration_versions.h"
#include "schemas/errors.h"

namespace speckle {

std::filesystem::path CalibrationFile(const std::string& given) {
  namespace fs = std::filesystem;
  const fs::path path(given);
  fs::path file;
  if (fs::is_regular_file(path) || (fs::exists(path) && !fs::is_directory(path)))
    file = path;
  else if (fs::exists(path / "calibration.json"))
    file = path / "calibration.json";
  else if (fs::is_directory(path / "calibrations"))
    file = NewestCalibrationVersion(path, "run run-pipeline on it first") / "calibration.json";
  else if (fs::exists(path / "session.json"))
    throw InputError(given + ": a session with no calibration yet (run run-pipeline " + given +
                     " first; or were the arguments swapped?)");
  else
    throw InputError(given + (fs::exists(path) ? "" : ": no such file or folder") +
                     ": expected a session, a calibration version folder or a calibration.json");
  // A pipe or a device would block the reader, or feed it forever.
  if (!fs::is_regular_file(file))
    throw InputError(file.string() + ": not a regular file (expected a calibration.json)");
  return file;
}

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
