#pragma once
// What a depth-model fit is asked to do (DepthFitOptions), where it starts,
// what the cameras' uncertainty gives it, and the time its parts took.
#include <cstddef>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "model/depth_model.h"

namespace speckle {

// Where a fit starts instead of the model's initial values: the parameters of
// an earlier fit of a related model, matched by block (the base form's when
// it is the same form, each free effect's by name). A candidate that adds one
// effect to the current model then starts where the current model ended, and
// only the new effect's parameters start from scratch.
struct WarmStart {
  model::BaseForm form = model::BaseForm::kReciprocal;
  std::vector<double> base;
  std::map<std::string, std::vector<double>> effects;
};

struct DepthFitOptions {
  double huber_raw = 0;  // > 0: Huber loss with this scale (raw units)
  // Readings in millimetres (a driver's depth image): each residual is
  // weighted by (1 m / z)^2, z the sample's reading. One raw disparity step
  // is about 3 z^2 mm at z metres, and a board pose's depth error grows with
  // z^2 too, so far samples are noisier by that factor and the weighted fit
  // is the efficient one (bench/results/hunt.md, the millimetre drift row).
  // Residuals, held-out errors and the floor stay in millimetres.
  bool millimetre_readings = false;
  // Cross-validation folds over poses (0: none). The same refits give a
  // grouped jackknife covariance: samples of one pose share its pose error,
  // so they are not independent.
  int folds = 10;
  int max_iterations = 100;
  // The held-out folds and the camera perturbations refit on an even
  // subsample of at most this many samples (every sample is still predicted):
  // board-plane sessions have 10^5 pixels, and the refits dominate the time.
  std::size_t max_refit_samples = 30000;
  // > 0: each camera perturbation is also a free direction of the true
  // depths, its weight bounded to +- this many sigma, so the fit may move the
  // cameras within their uncertainty (what the diagnosis compares candidate
  // effects with). The perturbations then give no covariance part.
  double camera_freedom_sigma = 0;
  // Non-empty: on a terminal, the refits report "<progress>: fold k of n" as
  // they end (see stages/step_clock.h); empty: quiet (nested fits).
  std::string progress;
  std::optional<WarmStart> start;  // none: the model's initial values
  // Models with at least this many parameters take their covariance from
  // the normal equations, and when an effect gives its samples' support
  // (effect.h) are solved with a sparse Cholesky of the Jacobian's nonzeros
  // (see lab/fit/solve.cc); the rest are solved dense.
  std::size_t sparse_from_parameters = 64;
  // In such a model, an effect that gives each sample's support (effect.h)
  // has one block per parameter, so each sample holds only those it reaches;
  // false keeps one block per effect (Ceres' dynamic sparsity: the same fit,
  // slower; for comparison).
  bool split_by_support = true;

  // False, with the first rule broken in *why (naming its field), for
  // options no fit can run with.
  bool IsValid(std::string* why) const;
};

// Wall-clock seconds of a fit's parts (report.json step_seconds). The camera
// refits run side by side, and so do the folds: each keeps its own time.
struct FitSeconds {
  double pre_fit = 0;  // the base form alone, for the effects' raw covariate
  double fit = 0;      // all samples
  double covariance = 0;
  std::vector<double> camera_refits;              // one per camera perturbation
  std::vector<double> folds;                      // one per held-out fold
  double camera_refits_wall = 0, folds_wall = 0;  // each group from start to end
  double total = 0;
};

// The true depths are only as good as the cameras that measured them. Each
// perturbation is every sample's depth under a one-sigma change of one
// calibration input (the colour focal length, the IR focal length through the
// extrinsics, ...); the fit is repeated on each and the parameters' shifts
// enter the covariance.
struct DepthPerturbations {
  std::vector<std::vector<double>> depths;  // [camera input][sample]
  // The first this many moved cameras fitted apart from the depth model:
  // what they change, no depth model removes, and the noise floor counts it
  // (DepthFit::camera_raw_rms). The rest moved cameras fitted together with
  // it (the joint board-plane fit), whose residuals the data already
  // balanced: they widen the parameters only.
  std::size_t in_floor = std::numeric_limits<std::size_t>::max();
  std::size_t size() const { return depths.size(); }
  bool empty() const { return depths.empty(); }
};

}  // namespace speckle
