#pragma once
// One Ceres solve of a depth model on a set of samples: the problem built
// from their residual blocks (residual_blocks.h), the solver chosen for the
// model's size and sparsity, the result read back.
#include <ceres/ceres.h>

#include <memory>
#include <string>
#include <vector>

#include "lab/fit/fit_options.h"
#include "model/depth_model.h"
#include "stages/records.h"

namespace speckle::fitting {

// The cameras free to move within their uncertainty (see
// DepthFitOptions::camera_freedom_sigma): perturbations are indexed like the
// samples from `first`.
struct CameraFreedom {
  const DepthPerturbations* perturbations = nullptr;
  const PairedSample* first = nullptr;
  double bound_sigma = 0;
};

struct Solved {
  std::unique_ptr<model::DepthModel> model;
  std::vector<double> camera_shift;  // one weight per perturbation (camera freedom)
  bool converged = false;
  // False when Ceres failed (e.g. "Residual and Jacobian evaluation failed")
  // or left a parameter not finite: nothing may be read from such a fit,
  // least of all its covariance (Eigen's SVD of a NaN Jacobian crashes).
  bool usable = false;
  std::string report;
  // One Huber loss for every residual, declared before the problem that
  // uses it so that it outlives it (one each cost 10 MB at 316,000 samples).
  std::unique_ptr<ceres::LossFunction> loss;
  std::unique_ptr<ceres::Problem> problem;
  std::vector<double*> blocks;
};

// start: flat parameters to begin from (the full fit's, for the camera
// refits: they land near it in a few iterations instead of a few dozen).
Solved Solve(const DepthFitOptions& options, const model::ModelDefinition& definition,
             const std::vector<const PairedSample*>& samples, const std::vector<double>* depths = nullptr,
             const std::vector<double>* start = nullptr, const CameraFreedom* freedom = nullptr);

// The flat start of `definition` under `start`: blocks that match take its
// values, the others (and frozen effects) keep their initial ones.
std::vector<double> StartValues(const model::ModelDefinition& definition, const WarmStart& start);

// A sample's true depth, with the cameras where the fit moved them.
double TrueDepth(const Solved& fitted, const std::vector<PairedSample>& samples,
                 const DepthPerturbations& perturbations, std::size_t i);

}  // namespace speckle::fitting
