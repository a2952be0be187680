#include "model/depth_model.h"

#include "schemas/errors.h"
#include "schemas/json_fields.h"

namespace speckle::model {

std::string ModelDefinition::Describe() const {
  std::string text = Info(form).name;
  for (const auto& e : effects) text += " + " + e.name;
  return text;
}

EffectSpec EffectSpecFromJson(const nlohmann::json& json, const std::string& where) {
  EffectSpec spec;
  if (json.is_string()) {
    spec.name = json.get<std::string>();
    CreateEffect(spec);
    return spec;
  }
  if (!json.is_object()) throw InputError(where + ": expected an effect name or an object");
  if (json.contains("formula")) {
    nlohmann::json formula = json;
    formula.erase("frozen");
    spec.formula = FormulaSpecFromJson(formula, where);
    spec.name = spec.formula->name;
    if (json.contains("frozen") && !json["frozen"].is_boolean())
      throw InputError(where + ".frozen: expected true or false");
    spec.frozen = json.value("frozen", false);
    return spec;
  }
  JsonFields f(json, where);
  spec.name = f.Required<std::string>("name");
  spec.frozen = f.Optional<bool>("frozen", false);
  const nlohmann::json initial = f.Optional<nlohmann::json>("initial", nlohmann::json::object());
  if (!initial.is_object()) throw InputError(f.Path("initial") + ": expected an object of parameter values");
  f.RejectUnknownKeys();
  const auto effect = CreateEffect(spec);
  for (const auto& [name, value] : initial.items()) {
    bool known = false;
    for (const auto& p : effect->Parameters()) known = known || p.name == name;
    if (!known) throw InputError(f.Path("initial") + "." + name + ": effect " + spec.name + " has no such parameter");
    if (!value.is_number()) throw InputError(f.Path("initial") + "." + name + ": expected a number");
    spec.initial[name] = value.get<double>();
  }
  return spec;
}

nlohmann::json ToJson(const EffectSpec& spec) {
  if (spec.formula) {
    nlohmann::json j = ToJson(*spec.formula);
    j["frozen"] = spec.frozen;
    return j;
  }
  if (!spec.frozen && spec.initial.empty()) return spec.name;
  return {{"name", spec.name}, {"frozen", spec.frozen}, {"initial", spec.initial}};
}

std::unique_ptr<Effect> CreateEffect(const EffectSpec& spec) {
  return spec.formula ? CreateFormulaEffect(*spec.formula) : CreateCompiledEffect(spec.name);
}

DepthModel::DepthModel(const ModelDefinition& definition)
    : definition_(definition), base_(Info(definition.form).initial) {
  for (const auto& spec : definition.effects) {
    effects_.push_back(CreateEffect(spec));
    std::vector<double>& values = effect_parameters_.emplace_back();
    for (const auto& p : effects_.back()->Parameters()) {
      const auto it = spec.initial.find(p.name);
      values.push_back(it == spec.initial.end() ? p.initial : it->second);
    }
  }
}

DepthModel::DepthModel(const DepthModel& other) : DepthModel(other.definition_) {
  base_ = other.base_;
  effect_parameters_ = other.effect_parameters_;
}

double DepthModel::RawOffset(const Covariates& c) const {
  double offset = 0;
  for (std::size_t k = 0; k < effects_.size(); ++k) offset += effects_[k]->RawOffset(effect_parameters_[k].data(), c);
  return offset;
}

double DepthModel::PredictRaw(double depth_m, const Covariates& c) const {
  return RawFromDepth(definition_.form, base_.data(), depth_m) + RawOffset(c);
}

double DepthModel::Depth(const Covariates& c) const {
  return DepthFromRaw(definition_.form, base_.data(), c.raw - RawOffset(c));
}

std::vector<double> DepthModel::Flat() const {
  std::vector<double> all = base_;
  for (const auto& p : effect_parameters_) all.insert(all.end(), p.begin(), p.end());
  return all;
}

void DepthModel::SetFlat(const std::vector<double>& values) {
  std::size_t i = 0;
  for (double& v : base_) v = values.at(i++);
  for (auto& p : effect_parameters_)
    for (double& v : p) v = values.at(i++);
}

std::vector<ParameterName> DepthModel::FlatNames() const {
  std::vector<ParameterName> names;
  const BaseFormInfo& info = Info(definition_.form);
  for (std::size_t i = 0; i < info.parameters.size(); ++i) names.push_back({"base", info.parameters[i], info.units[i]});
  for (const auto& e : effects_)
    for (const auto& p : e->Parameters()) names.push_back({e->Name(), p.name, p.unit});
  return names;
}

}  // namespace speckle::model
