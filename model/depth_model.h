#pragma once
// The depth model as a composition: a base form of a corrected raw value,
//   depth = base_form(raw - sum of effect offsets),
// so the raw value the model predicts for a true depth z is
//   raw = base_form^-1(z) + sum of effect offsets.
// The base form's parameters and each effect's are separate blocks.
#include <map>
#include <memory>
#include <optional>

#include "model/base_form.h"
#include "model/effect.h"
#include "model/formula_effect.h"

namespace speckle::model {

struct EffectSpec {
  std::string name;
  std::optional<FormulaSpec> formula;     // absent: a compiled effect of that name
  bool frozen = false;                    // keep its parameters at their initial values
  std::map<std::string, double> initial;  // overrides of initial values, by parameter name
};

struct ModelDefinition {
  BaseForm form = BaseForm::kReciprocal;
  std::vector<EffectSpec> effects;
  std::string Describe() const;  // e.g. "reciprocal + radial_billow + thermal_drift"
};

// `where` names the spec in messages. Throws InputError.
EffectSpec EffectSpecFromJson(const nlohmann::json& json, const std::string& where);
nlohmann::json ToJson(const EffectSpec& spec);

struct ParameterName {
  std::string block;  // "base" or the effect's name
  std::string name, unit;
};

class DepthModel {
 public:
  explicit DepthModel(const ModelDefinition& definition);  // throws InputError
  DepthModel(const DepthModel& other);
  DepthModel& operator=(const DepthModel&) = delete;

  const ModelDefinition& Definition() const { return definition_; }
  const std::vector<std::unique_ptr<Effect>>& Effects() const { return effects_; }
  std::vector<double>& Base() { return base_; }
  const std::vector<double>& Base() const { return base_; }
  std::vector<double>& EffectParameters(std::size_t k) { return effect_parameters_[k]; }
  const std::vector<double>& EffectParameters(std::size_t k) const { return effect_parameters_[k]; }

  double RawOffset(const Covariates& c) const;
  double PredictRaw(double depth_m, const Covariates& c) const;
  double Depth(const Covariates& c) const;

  // All parameters in one vector: base first, then each effect's.
  std::vector<double> Flat() const;
  void SetFlat(const std::vector<double>& values);
  std::vector<ParameterName> FlatNames() const;

 private:
  ModelDefinition definition_;
  std::vector<double> base_;
  std::vector<std::unique_ptr<Effect>> effects_;
  std::vector<std::vector<double>> effect_parameters_;
};

std::unique_ptr<Effect> CreateEffect(const EffectSpec& spec);  // throws InputError

}  // namespace speckle::model
