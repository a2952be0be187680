#pragma once
// Stage 9: fit the depth model (a base form plus effects) to paired samples
// with Ceres. Residuals are in raw units (the sensor's noise is in the raw
// value; fitting depth against noisy raw values would be biased); depth
// residuals in mm are reported too. Cross-validation holds out whole board
// poses, never single samples of a pose, whose errors are correlated.
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "lab/fit/fit_options.h"
#include "lab/fit/fit_samples.h"
#include "lab/stats/residual_stats.h"
#include "model/depth_model.h"
#include "stages/records.h"

namespace speckle {

struct DepthFit {
  model::ModelDefinition definition;
  std::vector<double> parameters;  // flat: base form's, then each effect's
  std::vector<model::ParameterName> names;
  std::vector<double> sigma;          // standard deviations from the covariance (samples + cameras)
  std::vector<double> sigma_samples;  // from the samples' scatter alone (poses as the independent units)
  std::vector<double> sigma_cameras;  // from the cameras' uncertainty alone (the perturbations)
  std::vector<std::vector<double>> covariance;
  // Free parameters the samples do not determine (flat indices): their
  // effect on every sample's raw value is zero, or the same as other
  // parameters'. Their sigmas are NaN.
  std::vector<std::size_t> unidentified;
  ResidualStats raw;           // measured raw - raw the model predicts for the true depth
  ResidualStats depth_mm;      // model depth of the measured raw - true depth
  ResidualStats held_out_raw;  // the same, each pose predicted by a fit without it
  ResidualStats held_out_mm;
  std::vector<double> camera_shift_sigma;  // with camera freedom: each perturbation's fitted weight
  // Per perturbation counted in the floor (DepthPerturbations::in_floor):
  // the RMS change of the raw residuals when the model is refitted to it,
  // what a one-sigma error of that camera input leaves that no depth model
  // removes.
  std::vector<double> camera_raw_rms;
  std::vector<double> residual_raw;           // per sample, in input order
  std::vector<double> held_out_residual_raw;  // per sample (NaN where no fold predicted it)
  // The residuals' unit, as fitted (DepthFitOptions::millimetre_readings):
  // millimetres read, else raw disparity. Whatever judges the fit reads it here.
  bool millimetre_readings = false;
  bool converged = false;
  std::string solver_report;
  FitSeconds seconds;

  model::DepthModel Model() const;  // the fitted model
};

// The parameters a fit ended at, as a start for related models.
WarmStart WarmStartFrom(const DepthFit& fit);

StageResult<DepthFit> RunDepthModelFit(const DepthFitOptions& options, const model::ModelDefinition& definition,
                                       const std::vector<PairedSample>& samples,
                                       const DepthPerturbations& perturbations = {});

// A model's error held out by pose, without the fit to every sample, its
// residuals or its covariance: all that comparing models reads (the
// diagnosis's candidates), at the cost of the folds alone. The folds are
// RunDepthModelFit's (they start from the model's initial values either
// way), so the held-out residuals are the same.
struct HeldOutFit {
  std::vector<double> held_out_residual_raw;  // per sample (NaN where no fold predicted it)
  ResidualStats held_out_raw;
  std::size_t parameters = 0;
  // Where the held-out samples' predictions rest on estimates made without
  // their depths (the joint problem's held-out boards, placed by their colour
  // corners and outlines, and the cameras fitted to the other poses): each
  // prediction's sigma (raw) from those estimates' uncertainty, else empty.
  std::vector<double> held_out_prediction_sigma_raw;
  // The folds fitted the depth camera's principal point to the depth image
  // alone (no IR recording, not given): a shift of the depth image from the
  // IR image (depth_grid_offset) is then that principal point, not an effect.
  bool principal_point_from_depth_image = false;
};
// With perturbations and options.camera_freedom_sigma > 0, each fold moves
// the cameras within their uncertainty too, as RunDepthModelFit does.
StageResult<HeldOutFit> RunHeldOutFit(const DepthFitOptions& options, const model::ModelDefinition& definition,
                                      const std::vector<PairedSample>& samples,
                                      const DepthPerturbations& perturbations = {});

}  // namespace speckle
