#include "pipeline/artifacts.h"

#include <spdlog/spdlog.h>

#include "apply/undistortion_grid_file.h"
#include "pipeline/report_html.h"
#include "pipeline/samples_file.h"
#include "schemas/atomic_file.h"
#include "schemas/atomic_folder.h"
#include "schemas/calibration_versions.h"
#include "schemas/json_fields.h"
#include "schemas/staging.h"

namespace speckle {

namespace fs = std::filesystem;

nlohmann::json SessionHistory(const fs::path& session_dir) {
  nlohmann::json history = nlohmann::json::array();
  for (const auto& v : CalibrationVersions(session_dir)) {
    // History is informative: a version this tool cannot read is listed without numbers.
    nlohmann::json row = {{"version", v.filename().string()}};
    try {
      const nlohmann::json c = ReadJsonFile(v / "calibration.json");
      row["model"] = c.at("model").at("name");
      row["held_out_raw"] = c.at("metrics").at("held_out_raw").at("rms");
      row["held_out_mm"] = c.at("metrics").at("held_out_mm").at("rms");
      row["parent_version"] = c.value("parent_version", nlohmann::json(nullptr));
    } catch (const std::exception& e) {
      row["unreadable"] = e.what();
    }
    history.push_back(row);
  }
  return history;
}

fs::path WriteCalibrationVersion(const fs::path& session_dir, VersionContent content) {
  const fs::path root = session_dir / "calibrations";
  fs::create_directories(root);
  nlohmann::json history = SessionHistory(session_dir);
  history.push_back({{"version", "this"},
                     {"model", content.calibration["model"]["name"]},
                     {"held_out_raw", content.calibration["metrics"]["held_out_raw"]["rms"]},
                     {"held_out_mm", content.calibration["metrics"]["held_out_mm"]["rms"]},
                     {"parent_version", content.calibration["parent_version"]}});
  content.report["history"] = history;
  content.report["plots"] = content.plots;
  const std::optional<std::string> html = ReportHtml(content.report);
  if (!html) spdlog::warn("report.html not written: the report's front-end assets are missing (run scripts/setup.sh)");
  RefuseSymlinkInside(session_dir, root);
  RemoveStaleStaging(root);
  return WriteFolderAside(
      IncomingPathIn(root),
      [&](const fs::path& staging) {
        WriteFileAtomically(staging / "calibration.json", content.calibration.dump(2) + "\n");
        WriteFileAtomically(staging / "report.json", content.report.dump(2) + "\n");
        if (html) WriteFileAtomically(staging / "report.html", *html);
        WriteSamples(staging / "samples.h5", content.samples, content.perturbations,
                     content.board_frames ? *content.board_frames : std::vector<joint::BoardFrame>{});
        if (content.grid) WriteGrid(staging / "undistortion_grid.h5", *content.grid);
      },
      [&](const fs::path& staging) { return PublishCalibrationVersion(session_dir, staging); });
}

}  // namespace speckle
