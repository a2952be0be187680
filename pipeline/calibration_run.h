#pragma once
// One calibration: the flow graph, then fits of every base form before and
// after undistortion, the chosen model, and the measures the report shows.
#include <filesystem>
#include <map>

#include "lab/model_lab.h"
#include "pipeline/calibration_graph.h"

namespace speckle {

struct WallFlatness {
  int snapshot_frame = 0;
  double true_raw = 0;
  double sigma_before = 0;  // raw scatter of the wall's inliers
  double sigma_after = 0;   // after a grid built without this wall (held out)
  double seconds = 0;       // wall-clock time of its scatter (the hold-out grids are built together first)
};

// Wall-clock seconds of what follows the graph (report.json step_seconds).
struct RunSeconds {
  double camera_perturbations = 0;  // the extrinsics refitted under each camera input's sigma
  double wall_hold_outs = 0;        // every wall's held-out grid, start to end
  double total = 0;                 // the whole run, graph included
};

struct CalibrationRun {
  PipelineResult pipeline;
  ModelSpec spec;
  DepthPerturbations perturbations;
  ModelLab lab;
  std::vector<WallFlatness> walls;
  double wall_sigma_reduction = 0;  // 1 - mean(after) / mean(before)
  RunSeconds seconds;
};

// Throws InputError when no frame could be paired (nothing to calibrate).
CalibrationRun RunCalibration(const std::filesystem::path& session_dir, const PipelineOptions& options,
                              const ModelSpec& spec);

}  // namespace speckle
