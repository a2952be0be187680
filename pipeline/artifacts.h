#pragma once
// A run's artifacts: a new immutable version directory under the session,
// calibrations/vNNNN/, holding calibration.json, report.json, samples.h5 (the
// paired samples, so a re-fit needs no detection) and undistortion_grid.h5.
// Written in a hidden temporary directory and renamed into place: a crash
// leaves no partial version, and earlier versions are never touched.
#include <filesystem>
#include <nlohmann/json.hpp>

#include <vector>

#include "lab/fit/depth_fit.h"
#include "stages/undistortion_grid.h"

#include "lab/joint/joint_calibration.h"

namespace speckle {

struct VersionContent {
  nlohmann::json calibration, report;
  const std::vector<PairedSample>& samples;
  const DepthPerturbations& perturbations;
  const UndistortionGrid* grid = nullptr;
  nlohmann::json plots;  // PlotDataJson: goes into report.json and report.html
  // Cached for a refit that re-runs the joint calibration; none when the cameras were not its.
  const std::vector<joint::BoardFrame>* board_frames = nullptr;
};
// Writes every artifact, with the session's history of versions added to the
// report, and returns the new version directory.
std::filesystem::path WriteCalibrationVersion(const std::filesystem::path& session_dir, VersionContent content);

}  // namespace speckle
