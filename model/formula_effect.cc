#include "model/formula_effect.h"

#include <muParser.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <regex>
#include <set>
#include <shared_mutex>
#include <unordered_map>

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

// The formula's top-level summands, each with its sign ("a*x + b*y - c" ->
// "a*x", "+b*y", "-c"): a '+' or '-' outside brackets that follows an operand
// (not an exponent's sign, not a unary one). Whether their sum is the formula
// (a ternary or comparison can bind looser than '+') is checked numerically
// by the caller.
std::vector<std::string> TopLevelSummands(const std::string& formula) {
  std::vector<std::string> summands;
  std::string current;
  int depth = 0;
  char previous = 0;  // the last non-space character
  for (std::size_t i = 0; i < formula.size(); ++i) {
    const char ch = formula[i];
    depth += ch == '(' ? 1 : ch == ')' ? -1 : 0;
    const bool operand_end =
        std::isalnum(static_cast<unsigned char>(previous)) || previous == ')' || previous == '.' || previous == '_';
    const bool exponent =
        (previous == 'e' || previous == 'E') && i >= 2 && std::isdigit(static_cast<unsigned char>(formula[i - 2])) &&
        (current.size() < 2 || !std::isalpha(static_cast<unsigned char>(current[current.size() - 2])));
    if (depth == 0 && (ch == '+' || ch == '-') && operand_end && !exponent) {
      summands.push_back(current);
      current.clear();
    }
    current += ch;
    if (!std::isspace(static_cast<unsigned char>(ch))) previous = ch;
  }
  summands.push_back(current);
  return summands;
}

class FormulaEffect final : public Effect {
 public:
  explicit FormulaEffect(const FormulaSpec& spec) : spec_(spec), values_(spec.parameters.size(), 0.0) {
    const std::string where = "formula effect \"" + spec.name + "\"";
    // Assignment would let a formula change its inputs: arithmetic only.
    if (std::regex_search(spec.formula, std::regex(R"((^|[^=<>!])=($|[^=]))"))) {
      throw InputError(where + ": \"" + spec.formula +
                       "\" assigns a value; a formula must be one arithmetic expression");
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
    for (std::size_t i = 0; i < kCovariateFields.size(); ++i)
      if (parser_.GetUsedVar().count(kCovariateFields[i].name)) read_fields_.push_back(i);
    linear_ = LinearInParameters();
    if (linear_) summands_ = Summands();
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
    // Only samples a gradient was asked for are cached: a one-off prediction
    // costs one parser run, not n + 1.
    if (const std::vector<double>* linear = LinearTerms(c, false)) {
      double value = (*linear)[0];
      for (std::size_t i = 0; i < values_.size(); ++i) value += (*linear)[i + 1] * p[i];
      return value;
    }
    return Evaluate(p, c);
  }

  double Evaluate(const double* p, const Covariates& c) const {
    covariates_ = c;
    for (std::size_t i = 0; i < values_.size(); ++i) values_[i] = p[i];
    return parser_.Eval();
  }

  double RawOffset(const double* p, const Covariates& c, double* gradient) const override {
    if (const std::vector<double>* linear = LinearTerms(c, true)) {
      std::copy(linear->begin() + 1, linear->end(), gradient);
      return RawOffset(p, c);
    }
    const double value = Evaluate(p, c);
    // Central differences, moving one parameter of the parser's own values at a time.
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
  // A formula linear in its parameters is a value at zero plus each
  // parameter times a term that depends on the sample alone: those n + 1
  // numbers are computed once per sample (n + 1 parser evaluations, each
  // unit step exact) and every later evaluation of that sample, value or
  // gradient, is a dot product instead of 2n + 1 parser runs (a 60-parameter
  // formula over Herrera's samples: see README). Null when the formula is
  // not linear, or the cache is full.
  const std::vector<double>* LinearTerms(const Covariates& c, bool add) const {
    if (!linear_) return nullptr;
    // The terms depend on the covariates the formula reads, and on no other:
    // samples that differ elsewhere (the raw value, undistorted or not) share them.
    Key key;
    for (std::size_t i : read_fields_) key.values[i] = c.*kCovariateFields[i].field;
    {
      const std::shared_lock lock(cache_->mutex);
      if (const auto found = cache_->terms.find(key); found != cache_->terms.end()) return &found->second;
      if (!add || cache_->terms.size() * (values_.size() + 1) > kMaxCachedTerms) return nullptr;
    }
    std::vector<double> terms(values_.size() + 1, 0.0);
    covariates_ = c;
    std::fill(values_.begin(), values_.end(), 0.0);
    // Each summand is evaluated at zero and once per parameter it holds (a
    // sum of 60 one-parameter terms: 120 small evaluations, not 61 of the
    // whole formula).
    for (const Summand& summand : summands_) {
      const double zero = summand.parser->Eval();
      terms[0] += zero;
      for (std::size_t i : summand.parameters) {
        values_[i] = 1;
        terms[i + 1] += summand.parser->Eval() - zero;
        values_[i] = 0;
      }
    }
    const std::unique_lock lock(cache_->mutex);
    return &cache_->terms.emplace(key, std::move(terms)).first->second;  // nodes never move: the pointer stays valid
  }
  struct Key {
    std::array<double, kCovariateFields.size()> values{};
    bool operator==(const Key& other) const { return values == other.values; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::size_t h = 1469598103934665603ull;
      for (double v : k.values) h = (h ^ std::hash<double>{}(v)) * 1099511628211ull;
      return h;
    }
  };
  static constexpr std::size_t kMaxCachedTerms = std::size_t{1} << 25;  // 256 MB of doubles

  // Whether the formula is linear in its parameters (k * x, a sum of terms
  // each with one parameter as a factor): at 8 spread covariate values, the
  // value at two random parameter vectors must equal the value at zero plus
  // each parameter times its unit step's change, to 1e-9. A formula that is
  // not (exp(-b * raw)) keeps central differences.
  bool LinearInParameters() const {
    const std::size_t n = values_.size();
    std::mt19937_64 rng(22);
    std::uniform_real_distribution<double> unit(-1, 1);
    for (int trial = 0; trial < 8; ++trial) {
      DrawCovariates(rng);
      std::fill(values_.begin(), values_.end(), 0.0);
      const double zero = parser_.Eval();
      std::vector<double> step(n);
      for (std::size_t i = 0; i < n; ++i) {
        values_[i] = 1;
        step[i] = parser_.Eval() - zero;
        values_[i] = 0;
      }
      for (int draw = 0; draw < 2; ++draw) {
        double predicted = zero, scale = std::abs(zero);
        for (std::size_t i = 0; i < n; ++i) {
          values_[i] = 3 * unit(rng);
          predicted += values_[i] * step[i];
          scale += std::abs(values_[i] * step[i]);
        }
        const double value = parser_.Eval();
        if (!std::isfinite(value) || !std::isfinite(predicted) ||
            std::abs(value - predicted) > 1e-9 * std::max(1.0, scale))
          return false;
      }
    }
    return true;
  }

  // One top-level summand of a linear formula: its own parser over the same
  // covariate and parameter storage, and the parameters it reads.
  struct Summand {
    std::unique_ptr<mu::Parser> parser;
    std::vector<std::size_t> parameters;
  };

  // The summands, when at the 8 points LinearInParameters draws their sum is
  // the formula's value to 1e-12 relative; else the whole formula as one.
  std::vector<Summand> Summands() const {
    std::vector<Summand> out;
    try {
      for (const std::string& text : TopLevelSummands(spec_.formula)) {
        Summand summand{std::make_unique<mu::Parser>(), {}};
        Define(*summand.parser, text);
        const auto used = summand.parser->GetUsedVar();
        for (std::size_t i = 0; i < spec_.parameters.size(); ++i)
          if (used.count(spec_.parameters[i].name)) summand.parameters.push_back(i);
        out.push_back(std::move(summand));
      }
    } catch (const mu::Parser::exception_type&) {
      return WholeFormula();
    }
    std::mt19937_64 rng(23);
    std::uniform_real_distribution<double> unit(-1, 1);
    for (int trial = 0; trial < 8; ++trial) {
      DrawCovariates(rng);
      for (double& v : values_) v = 3 * unit(rng);
      double sum = 0, scale = 0;
      for (const Summand& summand : out) {
        const double term = summand.parser->Eval();
        sum += term, scale += std::abs(term);
      }
      if (!std::isfinite(sum) || std::abs(sum - parser_.Eval()) > 1e-12 * std::max(1.0, scale)) return WholeFormula();
    }
    return out;
  }

  // The whole formula as its one summand, holding every parameter.
  std::vector<Summand> WholeFormula() const {
    Summand all{std::make_unique<mu::Parser>(), {}};
    Define(*all.parser, spec_.formula);
    for (std::size_t i = 0; i < values_.size(); ++i) all.parameters.push_back(i);
    std::vector<Summand> out;
    out.push_back(std::move(all));
    return out;
  }

  // A parser of `text` over this effect's covariate and parameter storage.
  void Define(mu::Parser& parser, const std::string& text) const {
    for (const auto& c : kCovariateFields) parser.DefineVar(c.name, &(covariates_.*c.field));
    for (std::size_t i = 0; i < spec_.parameters.size(); ++i) parser.DefineVar(spec_.parameters[i].name, &values_[i]);
    parser.SetExpr(text);
    parser.Eval();
  }

  // Covariates spread over their usual ranges, for the numeric checks.
  void DrawCovariates(std::mt19937_64& rng) const {
    std::uniform_real_distribution<double> unit(-1, 1);
    covariates_ = {};
    covariates_.raw = 700 + 300 * unit(rng), covariates_.u = 320 + 320 * unit(rng),
    covariates_.v = 240 + 240 * unit(rng);
    covariates_.x = 0.6 * unit(rng), covariates_.y = 0.45 * unit(rng), covariates_.time_s = 500 + 500 * unit(rng);
    covariates_.tilt_deg = 30 * unit(rng), covariates_.albedo = 0.5 + 0.5 * unit(rng),
    covariates_.raw_rate = 20 * unit(rng);
  }

  FormulaSpec spec_;
  bool linear_ = false;
  std::vector<std::size_t> read_fields_;  // indices into kCovariateFields
  std::vector<Summand> summands_;         // when linear_
  // Every instance of one formula shares its samples' terms: the fit, its
  // folds and camera refits (run side by side) and the diagnosis's candidates
  // each make their own model, and would otherwise compute them again.
  struct LinearCache {
    std::shared_mutex mutex;
    std::unordered_map<Key, std::vector<double>, KeyHash> terms;
  };
  static std::shared_ptr<LinearCache> SharedCache(const FormulaSpec& spec) {
    static std::mutex mutex;
    static std::map<std::string, std::weak_ptr<LinearCache>> caches;
    std::string id = spec.formula;
    for (const auto& p : spec.parameters) id += "|" + p.name;
    const std::lock_guard<std::mutex> lock(mutex);
    if (auto cache = caches[id].lock()) return cache;
    auto cache = std::make_shared<LinearCache>();
    caches[id] = cache;
    return cache;
  }
  std::shared_ptr<LinearCache> cache_ = SharedCache(spec_);
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
