#pragma once
// Why a model cannot be fitted to these samples, or why its fit cannot be
// judged: said in words that name the sample or the count, never a 0 or inf.
#include <optional>
#include <vector>

#include "lab/fit/depth_fit.h"

namespace speckle::fitting {

// Options no fit can run with (DepthFitOptions::IsValid), named.
std::optional<Rejection> InvalidOptions(const DepthFitOptions& options);

// A formula that divides by zero (or an effect outside its domain) would
// stall the solver without a word: name the sample instead.
std::optional<Rejection> NotFiniteAtStart(const model::ModelDefinition& definition,
                                          const std::vector<PairedSample>& samples);

// Without a held-out error the fit cannot be judged, and an RMS of 0 would
// read as perfect; non-finite residuals cannot be judged either.
std::optional<Rejection> Unjudgeable(const DepthFit& fit, const std::vector<PairedSample>& samples);

// Why these samples (with their fit raw) cannot be fitted with this model, if they cannot.
std::optional<Rejection> Unfittable(const model::ModelDefinition& definition, const std::vector<PairedSample>& samples);

}  // namespace speckle::fitting
