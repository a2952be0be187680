#include "lab/fit/fit_checks.h"

#include <cmath>
#include <set>
#include <string>

namespace speckle::fitting {
namespace {

// An effect's offset at p: from its terms when it is linear in its
// parameters (a formula's are computed once here and reused by the fit,
// instead of one run of the whole formula per sample first).
double OffsetAtStart(const model::Effect& effect, const std::vector<double>& p, const model::Covariates& c) {
  const double* terms = effect.LinearTerms(c);
  return terms ? model::LinearOffset(terms, p.data(), p.size()) : effect.RawOffset(p.data(), c);
}

}  // namespace

std::optional<Rejection> InvalidOptions(const DepthFitOptions& options) {
  std::string why;
  if (options.IsValid(&why)) return std::nullopt;
  return Rejection{"fit", "invalid fit options: " + why};
}

std::optional<Rejection> NotFiniteAtStart(const model::ModelDefinition& definition,
                                          const std::vector<PairedSample>& samples) {
  const model::DepthModel initial(definition);
  for (const auto& s : samples) {
    const model::Covariates c = FitCovariatesOf(s);
    for (std::size_t k = 0; k < initial.Effects().size(); ++k) {
      if (std::isfinite(OffsetAtStart(*initial.Effects()[k], initial.EffectParameters(k), c))) continue;
      return Rejection{"fit", "effect " + initial.Effects()[k]->Name() +
                                  " is not finite at its initial parameters for the sample of frame " +
                                  std::to_string(s.frame) + " at pixel (" + std::to_string(s.u) + ", " +
                                  std::to_string(s.v) + "), raw " + std::to_string(s.raw) +
                                  " (a division by zero, the root or logarithm of a negative number, or an overflow?)"};
    }
  }
  return std::nullopt;
}

std::optional<Rejection> Unjudgeable(const DepthFit& fit, const std::vector<PairedSample>& samples) {
  if (fit.held_out_raw.count == 0) {
    std::set<int> poses;
    for (const auto& s : samples) poses.insert(s.pose);
    // A fold is fitted to the other poses' samples, 3 per parameter at least
    // (HoldOutPoses): a large model on a small session fails there, not for
    // want of poses (the words said "needs at least 2 board poses" of a
    // 770-parameter pattern over 15).
    const std::size_t np = fit.parameters.size();
    if (poses.size() < 2)
      return Rejection{"fit",
                       "no held-out error: cross-validation by pose needs at least 2 board poses; the samples "
                       "come from " +
                           std::to_string(poses.size())};
    return Rejection{"fit", "no held-out error: with a pose held out, the other poses' samples are too few for " +
                                std::to_string(np) + " parameters (" + std::to_string(3 * np) + " needed; " +
                                std::to_string(samples.size()) + " samples from " + std::to_string(poses.size()) +
                                " poses in all)"};
  }
  if (!std::isfinite(fit.raw.rms) || !std::isfinite(fit.held_out_raw.rms))
    return Rejection{"fit", "the residuals are not finite (raw RMS " + std::to_string(fit.raw.rms) + ")"};
  return std::nullopt;
}

std::optional<Rejection> Unfittable(const model::ModelDefinition& definition,
                                    const std::vector<PairedSample>& samples) {
  if (auto rejection = NotFiniteAtStart(definition, samples)) return rejection;
  const std::size_t np = model::DepthModel(definition).Flat().size();
  if (samples.size() >= 3 * np) return std::nullopt;
  return Rejection{"fit", "too few paired samples (" + std::to_string(samples.size()) + ") for " + std::to_string(np) +
                              " parameters"};
}

}  // namespace speckle::fitting
