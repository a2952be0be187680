#include "model/formula_effect.h"

#include <muParser.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "model/compiled_formula.h"
#include "model/effect.h"
#include "schemas/errors.h"
#include "schemas/json_fields.h"

namespace speckle::model {
namespace {

class FormulaEffect final : public Effect {
 public:
  explicit FormulaEffect(const FormulaSpec& spec) : spec_(spec), compiled_(CompiledFormula::Of(spec)) {}

  std::string Name() const override { return spec_.name; }
  std::string Doc() const override { return spec_.doc; }
  const std::vector<EffectParameter>& Parameters() const override { return spec_.parameters; }
  std::vector<std::string> CovariatesRead() const override {
    std::vector<std::string> read;
    for (std::size_t i : compiled_->ReadFields()) read.push_back(kCovariateFields[i].name);
    std::sort(read.begin(), read.end());  // by name, as the parser lists them
    return read;
  }

  double RawOffset(const double* p, const Covariates& c) const override {
    // Only samples a gradient was asked for are kept: a one-off prediction
    // costs one parser run, not n + 1.
    if (const std::vector<double>* terms = compiled_->Terms(c, false))
      return LinearOffset(terms->data(), p, spec_.parameters.size());
    return Evaluate(p, c);
  }

  double RawOffset(const double* p, const Covariates& c, double* gradient) const override {
    if (const std::vector<double>* terms = compiled_->Terms(c, true)) {
      std::copy(terms->begin() + 1, terms->end(), gradient);
      return LinearOffset(terms->data(), p, spec_.parameters.size());
    }
    const double value = Evaluate(p, c);
    // Central differences, moving one parameter of the parser's own values at a time.
    Own& own = OwnParser();
    for (std::size_t i = 0; i < own.values.size(); ++i) {
      const double at = own.values[i], h = 1e-6 * std::max(1.0, std::abs(at));
      own.values[i] = at + h;
      const double plus = own.parser.Eval();
      own.values[i] = at - h;
      const double minus = own.parser.Eval();
      own.values[i] = at;
      gradient[i] = (plus - minus) / (2 * h);
    }
    return value;
  }

  const double* LinearTerms(const Covariates& c) const override {
    const std::vector<double>* terms = compiled_->Terms(c, true);
    return terms ? terms->data() : nullptr;
  }

 private:
  // A parser over this instance's own storage, for formulas that are not
  // linear (and linear ones past the cache): made on first use.
  struct Own {
    Covariates covariates;
    std::vector<double> values;
    mu::Parser parser;
  };
  Own& OwnParser() const {
    if (!own_) {
      own_ = std::make_unique<Own>();
      own_->values.assign(spec_.parameters.size(), 0.0);
      compiled_->Define(own_->parser, own_->covariates, own_->values, compiled_->Formula());
    }
    return *own_;
  }
  double Evaluate(const double* p, const Covariates& c) const {
    Own& own = OwnParser();
    own.covariates = c;
    std::copy(p, p + own.values.size(), own.values.begin());
    return own.parser.Eval();
  }

  FormulaSpec spec_;
  std::shared_ptr<CompiledFormula> compiled_;
  mutable std::unique_ptr<Own> own_;
};

}  // namespace

FormulaSpec FormulaSpecFromJson(const nlohmann::json& json, const std::string& where) {
  JsonFields f(json, where);
  FormulaSpec spec;
  spec.name = f.Required<std::string>("name");
  // A version that names a catalogue effect reads as holding it, and adding
  // the real one is then refused as "already there" (issue 47's probe).
  for (const EffectInfo& info : EffectCatalogue())
    if (info.name == spec.name)
      throw InputError(f.Path("name") + ": \"" + spec.name +
                       "\" is a catalogue effect's name; give the formula effect its own");
  spec.formula = f.Required<std::string>("formula");
  // muparser reads up to a NUL: "k * x\u0000 + q * y" would fit k * x alone.
  if (const auto nul = spec.formula.find('\0'); nul != std::string::npos)
    throw InputError(f.Path("formula") + ": holds a NUL character at position " + std::to_string(nul) +
                     "; the formula after it would be ignored");
  spec.doc = f.Optional<std::string>("doc", "formula effect: " + spec.formula);
  const nlohmann::json parameters = f.Optional<nlohmann::json>("parameters", nlohmann::json::array());
  if (!parameters.is_array()) throw InputError(f.Path("parameters") + ": expected an array");
  // A formula with nothing to fit is not an effect (and Ceres aborts on an
  // empty parameter block); past kMaxFormulaParameters the fit and its
  // cross-validation take minutes (a linear formula of 300 parameters has
  // 300 x 301 / 2 normal-equation terms per sample).
  if (parameters.empty() || parameters.size() > kMaxFormulaParameters) {
    throw InputError(f.Path("parameters") + ": expected 1 to " + std::to_string(kMaxFormulaParameters) +
                     " parameters to fit, found " + std::to_string(parameters.size()) +
                     (parameters.empty() ? " (a fixed correction has nothing to fit)" : ""));
  }
  for (std::size_t i = 0; i < parameters.size(); ++i) {
    JsonFields p(parameters[i], f.Path("parameters") + "[" + std::to_string(i) + "]");
    EffectParameter parameter;
    parameter.name = p.Required<std::string>("name");
    parameter.unit = p.Optional<std::string>("unit", "");
    parameter.initial = p.Optional<double>("initial", 0);
    parameter.lower = p.Optional<double>("lower", -1e30);
    parameter.upper = p.Optional<double>("upper", 1e30);
    if (!(parameter.lower <= parameter.initial && parameter.initial <= parameter.upper)) {
      throw InputError(p.Path("initial") + ": must lie within [lower, upper]");
    }
    p.RejectUnknownKeys();
    for (const auto& earlier : spec.parameters)
      if (earlier.name == parameter.name)
        throw InputError(p.Path("name") + ": \"" + parameter.name + "\" names an earlier parameter too");
    spec.parameters.push_back(parameter);
  }
  f.RejectUnknownKeys();
  CreateFormulaEffect(spec);  // validates the formula now, where the spec is named
  return spec;
}

nlohmann::json ToJson(const FormulaSpec& spec) {
  nlohmann::json parameters = nlohmann::json::array();
  for (const auto& p : spec.parameters) {
    parameters.push_back(
        {{"name", p.name}, {"unit", p.unit}, {"initial", p.initial}, {"lower", p.lower}, {"upper", p.upper}});
  }
  return {{"name", spec.name}, {"doc", spec.doc}, {"formula", spec.formula}, {"parameters", parameters}};
}

std::unique_ptr<Effect> CreateFormulaEffect(const FormulaSpec& spec) { return std::make_unique<FormulaEffect>(spec); }

}  // namespace speckle::model
