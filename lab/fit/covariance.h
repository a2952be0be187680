#pragma once
// A fit's covariance: the samples' part (independent samples, or a grouped
// jackknife over the pose folds where poses share errors) and the cameras'
// part (the fit redone under each camera perturbation).
#include <vector>

#include "lab/fit/depth_fit.h"
#include "lab/fit/solve.h"

namespace speckle::fitting {

using Matrix = std::vector<std::vector<double>>;

// Covariance of the free parameters, scaled by the residual variance (Ceres
// assumes unit-variance residuals), from the normal equations' Jacobi-scaled
// pseudo-inverse; frozen blocks have none. (Ceres' dense SVD of the whole
// Jacobian took 4.0 s of a 9.7 s fit of a 60-term formula over Herrera's
// 151,321 samples, and dropped directions for their units.) `unidentified`
// marks, per flat parameter, the free ones the samples do not
// determine (no effect on any sample's raw value, or the same as others').
Matrix IndependentCovariance(const DepthFitOptions& options, const Solved& solved,
                             const std::vector<PairedSample>& samples, const CameraFreedom* free_cameras,
                             double variance, std::vector<bool>* unidentified);

// The cameras' part of the covariance: the fit redone with the true depths of
// each camera perturbation (side by side, combined in order), and each one's
// raw RMS change into fit.camera_raw_rms. With the cameras free the
// perturbations were parameters instead, and are not refitted.
StageResult<Matrix> CameraCovariance(const DepthFitOptions& options, const model::ModelDefinition& definition,
                                     const std::vector<PairedSample>& samples, const DepthPerturbations& refitted,
                                     DepthFit& fit, FitSeconds& seconds);

// Grouped jackknife over the folds: (K-1)/K sum (p_k - mean)^2. Where most
// free parameters vary more over pose folds than the independent-sample
// covariance says, poses share errors and the jackknife is the honest one.
Matrix SamplesCovariance(const Matrix& independent, const std::vector<std::vector<double>>& fold_parameters);

// fit.covariance and its sigmas: the samples' part plus the cameras'. Frozen
// parameters have none (not even the jackknife's rounding); unidentified
// ones have NaN sigmas (no number would be honest) and are listed in
// fit.unidentified.
void SetCovariance(const Matrix& samples_part, const Matrix& cameras, const std::vector<bool>& unidentified,
                   DepthFit& fit);

}  // namespace speckle::fitting
