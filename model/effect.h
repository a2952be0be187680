#pragma once
// A physical effect of the depth model: a small correction to the raw value,
//   depth = base_form(raw - sum of effect offsets),
// with named parameters (units, initial values, bounds) fitted by Ceres. Each
// effect's parameters are one block, so any effect can be frozen.
//
// Recipe for a compiled effect (one header in model/effects/, no other file):
//  1. Copy the shortest header there (albedo_bias.h).
//  2. Set kName, kDoc (one line: the physics), Parameters(), CovariatesRead().
//  3. Write the templated RawOffset(p, c): the raw-unit offset the effect adds
//     to a sample with covariates c. T is double or a Ceres Jet: derivatives
//     come from automatic differentiation, a Jet of kJetStride parameters at
//     a time.
//  4. End with SPECKLE_MODEL_EFFECT(ClassName): the build collects the folder.
// An effect that only makes sense in one kind of session sets kUnits ("raw"
// or "millimetre"): the diagnosis then tries it only there.
// An effect with many parameters that enter linearly (a B-spline field) may
// also give static double RawOffsetAndGradient(p, c, gradient): the fit then
// uses it instead of autodiff, which would evaluate the effect once per
// kJetStride parameters.
// An effect whose sample reaches only a few of its many parameters (a
// B-spline field: 16 controls of hundreds) may give static int
// Support(c, indices): the parameters a sample's offset depends on, their
// count, or -1 for all of them; and with it static double
// RawOffsetOnSupport(p, c, gradient): the offset from those parameters alone,
// p and gradient (which may be null) in Support's order. Large fits then give each parameter its own
// Ceres block and each sample only its support, so the Jacobian's sparsity is
// known before the solve (Herrera's pattern fit: see lab/fit/residual_blocks.cc).
// An effect needs no rebuild at all as a formula in the model spec (see
// formula_effect.h).
#include <ceres/jet.h>

#include <algorithm>
#include <concepts>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/covariates.h"

namespace speckle::model {

struct EffectParameter {
  std::string name;
  std::string unit;
  double initial = 0;
  double lower = -1e30, upper = 1e30;
  // > 0: a weak Gaussian prior around the initial value with this sigma, in
  // the parameter's unit. Spatial fields need it: where no board ever was,
  // their control values would otherwise be free to extrapolate wildly.
  double prior_sigma = 0;
};

// Compiled effects are differentiated with Jets of this many parameters at a time.
inline constexpr int kJetStride = 8;
using Jet = ceres::Jet<double, kJetStride>;

class Effect {
 public:
  virtual ~Effect() = default;
  virtual std::string Name() const = 0;
  virtual std::string Doc() const = 0;
  virtual const std::vector<EffectParameter>& Parameters() const = 0;
  virtual std::vector<std::string> CovariatesRead() const = 0;
  virtual double RawOffset(const double* p, const Covariates& c) const = 0;
  // The offset and, into gradient[0 .. parameters), its derivative by each parameter.
  virtual double RawOffset(const double* p, const Covariates& c, double* gradient) const = 0;
  // For an effect linear in its parameters (offset = t[0] + sum of p[i] t[i + 1]):
  // its terms t at c, valid while the effect lives; null when not (the
  // default). A fit reads them once per sample instead of at every
  // evaluation (a formula effect: see lab/fit/residual_blocks.cc).
  virtual const double* LinearTerms(const Covariates&) const { return nullptr; }
  // Into indices, the parameters the offset at c depends on; returns their
  // count, or -1 when it may depend on every parameter (the default).
  virtual int Support(const Covariates&, int*) const { return -1; }
  virtual bool GivesSupport() const { return false; }
  // Only for an effect that gives its support, and a sample whose support is not -1.
  virtual double RawOffsetOnSupport(const double*, const Covariates&, double*) const {
    throw std::logic_error(Name() + " gives no support");
  }
};

// The offset of an effect linear in its n parameters p from its terms
// (Effect::LinearTerms): terms[0] + sum of terms[i + 1] p[i].
inline double LinearOffset(const double* terms, const double* p, std::size_t n) {
  double offset = terms[0];
  for (std::size_t i = 0; i < n; ++i) offset += terms[i + 1] * p[i];
  return offset;
}

template <class E>
concept HasAnalyticGradient = requires(const double* p, const Covariates& c, double* g) {
  { E::RawOffsetAndGradient(p, c, g) } -> std::convertible_to<double>;
};

template <class E>
concept HasSupport = requires(const double* p, const Covariates& c, int* indices, double* g) {
  { E::Support(c, indices) } -> std::convertible_to<int>;
  { E::RawOffsetOnSupport(p, c, g) } -> std::convertible_to<double>;
};

struct EffectInfo {
  std::string name;
  std::string doc;
  std::function<std::unique_ptr<Effect>()> create;
  // The depth units of the sessions the diagnosis tries it in: "any", "raw"
  // or "millimetre" (an effect header's optional kUnits).
  std::string units = "any";
  // Whether it applies to a session read in millimetres (else raw disparities).
  bool AppliesTo(bool millimetre_session) const {
    return units == "any" || units == (millimetre_session ? "millimetre" : "raw");
  }
};

template <class E>
constexpr const char* EffectUnits() {
  if constexpr (requires { E::kUnits; })
    return E::kUnits;
  else
    return "any";
}

bool RegisterEffect(EffectInfo info);
// Every compiled effect, sorted by name.
std::vector<EffectInfo> EffectCatalogue();
// Throws InputError naming the catalogue when `name` is unknown.
std::unique_ptr<Effect> CreateCompiledEffect(const std::string& name);

// Adapts an effect header's static members to the Effect interface.
template <class E>
class CompiledEffect final : public Effect {
 public:
  std::string Name() const override { return E::kName; }
  std::string Doc() const override { return E::kDoc; }
  const std::vector<EffectParameter>& Parameters() const override { return parameters_; }
  std::vector<std::string> CovariatesRead() const override { return E::CovariatesRead(); }
  double RawOffset(const double* p, const Covariates& c) const override { return E::RawOffset(p, c); }
  int Support(const Covariates& c, int* indices) const override {
    if constexpr (HasSupport<E>)
      return E::Support(c, indices);
    else
      return -1;
  }
  bool GivesSupport() const override { return HasSupport<E>; }
  double RawOffsetOnSupport(const double* p, const Covariates& c, double* gradient) const override {
    if constexpr (HasSupport<E>)
      return E::RawOffsetOnSupport(p, c, gradient);
    else
      return Effect::RawOffsetOnSupport(p, c, gradient);
  }
  double RawOffset(const double* p, const Covariates& c, double* gradient) const override {
    if constexpr (HasAnalyticGradient<E>) {
      return E::RawOffsetAndGradient(p, c, gradient);
    } else {
      const int n = static_cast<int>(parameters_.size());
      std::vector<Jet> jets(p, p + n);
      double value = E::RawOffset(p, c);
      for (int first = 0; first < n; first += kJetStride) {
        const int last = std::min(n, first + kJetStride);
        for (int i = 0; i < n; ++i) jets[i].v.setZero();
        for (int i = first; i < last; ++i) jets[i].v[i - first] = 1;
        const Jet offset = E::RawOffset(jets.data(), c);
        for (int i = first; i < last; ++i) gradient[i] = offset.v[i - first];
      }
      return value;
    }
  }

 private:
  std::vector<EffectParameter> parameters_ = E::Parameters();
};

#define SPECKLE_MODEL_EFFECT(Class)                                                                         \
  inline const bool kModelEffectRegistered_##Class =                                                        \
      ::speckle::model::RegisterEffect({Class::kName, Class::kDoc,                                          \
                                        [] {                                                                \
                                          return std::unique_ptr<::speckle::model::Effect>(                 \
                                              std::make_unique<::speckle::model::CompiledEffect<Class>>()); \
                                        },                                                                  \
                                        ::speckle::model::EffectUnits<Class>()});

}  // namespace speckle::model
