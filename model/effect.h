#pragma once
// A physical effect of the depth model: a small correction to the raw value,
//   depth = base_form(raw - sum of effect offsets),
// with named parameters (units, initial values, bounds) fitted by Ceres with
// automatic differentiation. Each effect's parameters are one block, so any
// effect can be frozen.
//
// Recipe for a compiled effect (one header in model/effects/, no other file):
//  1. Copy the shortest header there (albedo_bias.h).
//  2. Set kName, kDoc (one line: the physics), Parameters(), CovariatesRead().
//  3. Write the templated RawOffset(p, c): the raw-unit offset the effect adds
//     to a sample with covariates c. T is double or a Ceres Jet.
//  4. End with SPECKLE_MODEL_EFFECT(ClassName): the build collects the folder.
// An effect needs no rebuild at all as a formula in the model spec (see
// formula_effect.h).
#include <ceres/jet.h>

#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
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

// Ceres evaluates the model with these Jets (DynamicAutoDiffCostFunction's stride).
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
  virtual Jet RawOffset(const Jet* p, const Covariates& c) const = 0;
};

struct EffectInfo {
  std::string name;
  std::string doc;
  std::function<std::unique_ptr<Effect>()> create;
};

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
  Jet RawOffset(const Jet* p, const Covariates& c) const override { return E::RawOffset(p, c); }

 private:
  std::vector<EffectParameter> parameters_ = E::Parameters();
};

#define SPECKLE_MODEL_EFFECT(Class)                                                   \
  inline const bool kModelEffectRegistered_##Class = ::speckle::model::RegisterEffect( \
      {Class::kName, Class::kDoc, [] { return std::unique_ptr<::speckle::model::Effect>(std::make_unique<::speckle::model::CompiledEffect<Class>>()); }});

}  // namespace speckle::model
