#include "model/formula_effect.h"

#include <muParser.h>

#include <cmath>
#include <regex>
#include <set>

#include "schemas/errors.h"
#include "schemas/json_fields.h"

namespace speckle::model {
namespace {

// Names the parser met that are neither covariates nor parameters.
struct UnknownNames {
  std::set<std::string> names;
  double sink = 0;
};

double* RecordUnknown(const char* name, void* user) {
  auto* unknown = static_cast<UnknownNames*>(user);
  unknown->names.insert(name);
  return &unknown->sink;
}

class FormulaEffect final : public Effect {
 public:
  explicit FormulaEffect(const FormulaSpec& spec) : spec_(spec), values_(spec.parameters.size(), 0.0) {
    const std::string where = "formula effect \"" + spec.name + "\"";
    // Assignment would let a formula change its inputs: arithmetic only.
    if (std::regex_search(spec.formula, std::regex(R"((^|[^=<>!])=($|[^=]))"))) {
      throw InputError(where + ": \"" + spec.formula + "\" assigns a value; a formula must be one arithmetic expression");
    }
    std::string known;
    UnknownNames unknown;
    try {
      for (const auto& c : kCovariateFields) {
        parser_.DefineVar(c.name, &(covariates_.*c.field));
        known += std::string(known.empty() ? "" : ", ") + c.name;
      }
      for (std::size_t i = 0; i < spec.parameters.size(); ++i) {
        for (const auto& c : kCovariateFields) {
          if (spec.parameters[i].name == c.name)
            throw InputError(where + ": parameter \"" + c.name + "\" has a covariate's name; rename it");
        }
        parser_.DefineVar(spec.parameters[i].name, &values_[i]);
        known += ", " + spec.parameters[i].name;
      }
      parser_.SetVarFactory(RecordUnknown, &unknown);
      parser_.SetExpr(spec.formula);
      parser_.GetUsedVar();
      parser_.Eval();
      if (parser_.GetNumResults() != 1) throw InputError(where + ": \"" + spec.formula + "\" must be one expression");
    } catch (const mu::Parser::exception_type& e) {
      throw InputError(where + ": invalid formula \"" + spec.formula + "\": " + e.GetMsg());
    }
    if (!unknown.names.empty()) {
      throw InputError(where + ": unknown variable \"" + *unknown.names.begin() + "\" in \"" + spec.formula +
                       "\" (known: " + known + ")");
    }
    parser_.SetVarFactory(nullptr, nullptr);
  }

  std::string Name() const override { return spec_.name; }
  std::string Doc() const override { return spec_.doc; }
  const std::vector<EffectParameter>& Parameters() const override { return spec_.parameters; }
  std::vector<std::string> CovariatesRead() const override {
    std::vector<std::string> read;
    for (const auto& [name, pointer] : parser_.GetUsedVar()) {
      for (const auto& c : kCovariateFields)
        if (name == c.name) read.push_back(name);
    }
    return read;
  }

  double RawOffset(const double* p, const Covariates& c) const override {
    covariates_ = c;
    for (std::size_t i = 0; i < values_.size(); ++i) values_[i] = p[i];
    return parser_.Eval();
  }

  double RawOffset(const double* p, const Covariates& c, double* gradient) const override {
    // Central differences, moving one parameter of the parser's own values at a time.
    const double value = RawOffset(p, c);
    for (std::size_t i = 0; i < values_.size(); ++i) {
      const double at = values_[i], h = 1e-6 * std::max(1.0, std::abs(at));
      values_[i] = at + h;
      const double plus = parser_.Eval();
      values_[i] = at - h;
      const double minus = parser_.Eval();
      values_[i] = at;
      gradient[i] = (plus - minus) / (2 * h);
    }
    return value;
  }

 private:
  FormulaSpec spec_;
  mutable Covariates covariates_;
  mutable std::vector<double> values_;
  mutable mu::Parser parser_;
};

}  // namespace

FormulaSpec FormulaSpecFromJson(const nlohmann::json& json, const std::string& where) {
  JsonFields f(json, where);
  FormulaSpec spec;
  spec.name = f.Required<std::string>("name");
  spec.formula = f.Required<std::string>("formula");
  spec.doc = f.Optional<std::string>("doc", "formula effect: " + spec.formula);
  const nlohmann::json parameters = f.Optional<nlohmann::json>("parameters", nlohmann::json::array());
  if (!parameters.is_array()) throw InputError(f.Path("parameters") + ": expected an array");
  // A formula with nothing to fit is not an effect (and Ceres aborts on an
  // empty parameter block); past kMaxFormulaParameters the fit and its
  // cross-validation take minutes without a word.
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
    spec.parameters.push_back(parameter);
  }
  f.RejectUnknownKeys();
  CreateFormulaEffect(spec);  // validates the formula now, where the spec is named
  return spec;
}

nlohmann::json ToJson(const FormulaSpec& spec) {
  nlohmann::json parameters = nlohmann::json::array();
  for (const auto& p : spec.parameters) {
    parameters.push_back({{"name", p.name}, {"unit", p.unit}, {"initial", p.initial}, {"lower", p.lower}, {"upper", p.upper}});
  }
  return {{"name", spec.name}, {"doc", spec.doc}, {"formula", spec.formula}, {"parameters", parameters}};
}

std::unique_ptr<Effect> CreateFormulaEffect(const FormulaSpec& spec) { return std::make_unique<FormulaEffect>(spec); }

}  // namespace speckle::model
