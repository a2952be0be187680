#include "pipeline/parent_version.h"

#include "schemas/artifact_schema.h"

namespace speckle {

ParentVersion ReadParentVersion(const std::filesystem::path& version_dir) {
  ParentVersion parent;
  // Version 2 calibrations lack only depth_delay_s (unknown: null).
  nlohmann::json& calibration = parent.calibration =
      ReadArtifactJson(version_dir / "calibration.json", "speckle.calibration", kCalibrationSchemaVersion, 2);
  calibration["schema_version"] = kCalibrationSchemaVersion;
  auto& extrinsics = calibration["cameras"]["depth_from_colour"];
  if (!extrinsics.contains("depth_delay_s")) extrinsics["depth_delay_s"] = nullptr;
  // Before version 7 the cameras always came from the separate steps.
  if (!calibration["cameras"].contains("joint")) calibration["cameras"]["joint"] = nullptr;
  // Before version 6 what a joint board-plane fit did not determine was
  // written as 0.
  if (calibration["cameras"]["depth_intrinsics_source"] == "joint_board_planes") {
    extrinsics["outline_rms_px"] = nullptr;
    calibration["cameras"]["depth"]["rms_reprojection_px"] = nullptr;
  }
  if (extrinsics["translation_sigma_m"] == nlohmann::json({0.0, 0.0, 0.0})) extrinsics["translation_sigma_m"] = nullptr;
  // A refit keeps the parent's pipeline sections (frames, quads, snapshots)
  // and rewrites the model's; version 2 reports lack the depthboard quads,
  // versions 2 and 3 the walls' tilts (null: not measured).
  nlohmann::json& report = parent.report =
      ReadArtifactJson(version_dir / "report.json", "speckle.report", kReportSchemaVersion, 2);
  if (!report.contains("depthboard_quads"))
    report["depthboard_quads"] = {{"absent_because", "the parent version's report (schema 2) did not record them"}};
  else if (!report["depthboard_quads"].contains("board_size_in_depth"))
    report["depthboard_quads"]["board_size_in_depth"] = nullptr;  // before version 21: not measured
  for (auto& snapshot : report["planar_snapshots"])
    if (!snapshot.contains("tilt_deg")) snapshot["tilt_deg"] = nullptr;
  if (report["undistortion"].contains("walls") && !report["undistortion"].contains("max_wall_tilt_deg"))
    report["undistortion"]["max_wall_tilt_deg"] = nullptr;
  report["schema_version"] = kReportSchemaVersion;
  // The parent's times were its own run's; a refit has no graph.
  report["step_seconds"] = {{"graph", nullptr}, {"camera_perturbations", nullptr}, {"wall_hold_outs", nullptr}};
  return parent;
}

}  // namespace speckle
