#pragma once
// The candidate changes to the current model (each catalogue effect it lacks
// and the other base forms), each fitted and held out by pose on a subsample,
// judged by its per-pose gain over the current model and beyond what the
// cameras' freedom gives; then ranked, and the best paired with the others.
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "lab/diagnosis/diagnosis.h"

namespace speckle {

using CandidateModelList = std::vector<std::pair<std::string, model::ModelDefinition>>;

// What every candidate is compared on: an even subsample, the fit options,
// and the current model's held-out residuals fitted the same way (same
// subsample, folds and iterations), not its full fit's: a rich current model
// held out on all samples would make every candidate look worse.
struct Comparison {
  std::vector<std::size_t> chosen;  // indices of the subsample in the session's samples
  std::vector<PairedSample> subset;
  DepthFitOptions fit_options;
  DepthPerturbations perturbations;  // the session's, at the subsample
  // How the candidates are fitted: fit_options, with the cameras free as
  // well when the diagnosis judges beyond them.
  DepthFitOptions candidate_options;
  std::vector<double> baseline;
  // The current model with the cameras free to move within their
  // uncertainty: what a candidate must also beat (none without perturbations).
  std::optional<std::vector<double>> cameras_free;
  // Where models are held out when not in the depth fit (the joint
  // calibration's problem); empty after the current model failed there.
  // Models with more parameters than max_judged_parameters are held out in
  // the depth fit even so, against depth_fit_baseline.
  HeldOutJudge judge;
  std::size_t max_judged_parameters = 0;
  std::vector<double> depth_fit_baseline;
  bool Judged(const model::ModelDefinition& definition) const;
};

// The current model with each effect of the catalogue it lacks (and that the
// session's covariates can show), and with each other base form.
CandidateModelList CandidateModels(const model::ModelDefinition& current, const std::vector<PairedSample>& samples);

// The candidates' subsample and fit options; no fit yet.
Comparison ComparisonSubset(const DiagnosisOptions& options, const DepthFit& fit,
                            const std::vector<PairedSample>& samples, const DepthPerturbations& perturbations,
                            const HeldOutJudge& judge = {});

// Every candidate on its own, fitted and held out by pose on the subsample,
// side by side with the current model's refit and its fit with the cameras
// free (what each candidate is compared with): the largest candidate starts
// at once instead of after those two (Herrera's formula refit: see
// bench/results/speed.md). Into d.candidates; returns each fitted
// one's held-out residuals (for the pair search).
std::map<std::string, std::vector<double>> FitCandidates(const DiagnosisOptions& options,
                                                         const CandidateModelList& models, const DepthFit& fit,
                                                         Comparison& in, Diagnosis& d);

// Fitted candidates first, best first; those not fitted keep their order.
// Among those near the best, the one with fewest parameters leads.
void RankCandidates(const DiagnosisOptions& options, Diagnosis& d);

// One effect not enough: the recommended one with each other helpful
// candidate, judged against the recommended one alone by the same test.
void SearchPairs(const DiagnosisOptions& options, const model::ModelDefinition& current,
                 const std::vector<std::pair<std::string, model::ModelDefinition>>& models, const Comparison& in,
                 const std::vector<double>& single, Diagnosis& d);

}  // namespace speckle
