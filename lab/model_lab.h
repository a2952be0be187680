#pragma once
// The model part of a calibration, shared by run-pipeline and refit: fits of
// the spec's model and of the other base forms, before and after the
// undistortion grid, the chosen one, and the diagnosis of what is missing.
#include <limits>
#include <optional>

#include <nlohmann/json.hpp>

#include "lab/diagnosis/model_diagnosis.h"
#include "lab/model_spec.h"
#include "schemas/session_manifest.h"
#include "stages/undistortion_grid.h"

namespace speckle {

struct NamedFit {
  std::string name;  // e.g. "reciprocal", "reciprocal + thermal_drift +undistortion"
  bool undistorted = false;
  DepthFit fit;
};

struct ModelLabInput {
  ModelSpec spec;
  std::vector<PairedSample> samples;
  std::optional<UndistortionGrid> grid;
  DepthPerturbations perturbations;  // per camera input, every sample's depth moved by one sigma
  DepthUnits units = DepthUnits::kRaw11Bit;
  std::string session;               // for the commands the verdict suggests (ModelLab::verdict)
  std::string refit_tool = "refit";  // how the user calls refit, for the same commands
  DiagnosisOptions diagnosis;
  // Where the diagnosis holds candidates out: the joint calibration's
  // problem when the cameras came from it (lab/joint/joint_hold_out.h);
  // empty, the depth fit.
  HeldOutJudge judge = {};
};

struct ModelLab {
  std::vector<NamedFit> fits;
  int chosen = -1;
  Diagnosis diagnosis;
  // The diagnosis's verdict and its commands, written for the session
  // (lab/diagnosis/verdict_text.h).
  std::string verdict;
  nlohmann::json next_steps;
  const NamedFit& Chosen() const { return fits.at(static_cast<std::size_t>(chosen)); }
  // The input's samples, moved in (a session of 2000 frames holds 300,000,
  // 60 MB: one copy, not one per step), and the same through the grid when
  // there is one.
  std::vector<PairedSample> samples, undistorted;
  // The samples the chosen fit saw (undistorted when it uses the grid).
  const std::vector<PairedSample>& ChosenSamples() const { return Chosen().undistorted ? undistorted : samples; }
  // Wall-clock seconds: the spec's fits, the comparison fits (which run
  // beside the diagnosis; each fit's parts are in its FitSeconds), and the
  // whole lab (fits and diagnosis; the diagnosis's parts are in it).
  double spec_fits_seconds = 0, comparison_fits_seconds = 0, seconds = 0;
  int spec_fits = 0;  // how many of `fits` are the spec's (the first ones)
};

// Throws InputError when the spec's model cannot be fitted.
// The input's samples end up in ModelLab::samples.
ModelLab RunModelLab(ModelLabInput input);

}  // namespace speckle
