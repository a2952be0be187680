#include "model/compiled_formula.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <random>
#include <regex>
#include <set>

#include "schemas/errors.h"

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

}  // namespace

// Kept for the process's life, not only while some model holds it: between a
// refit's phases no model may be alive, and a weak reference compiled the
// formula (and computed its samples' terms) again in each. A process sees a
// few formulas (its model spec's), whose terms are bounded by kMaxCachedTerms.
std::shared_ptr<CompiledFormula> CompiledFormula::Of(const FormulaSpec& spec) {
  static std::mutex mutex;
  static std::map<std::string, std::shared_ptr<CompiledFormula>> compiled;
  std::string id = spec.formula;
  for (const auto& p : spec.parameters) id += "|" + p.name;
  const std::lock_guard<std::mutex> lock(mutex);
  std::shared_ptr<CompiledFormula>& found = compiled[id];
  if (!found) {
    try {
      found = std::make_shared<CompiledFormula>(spec);
    } catch (...) {
      compiled.erase(id);
      throw;
    }
  }
  return found;
}

CompiledFormula::CompiledFormula(const FormulaSpec& spec) : spec_(spec), values_(spec.parameters.size(), 0.0) {
  Validate();
  for (std::size_t i = 0; i < kCovariateFields.size(); ++i)
    if (parser_.GetUsedVar().count(kCovariateFields[i].name)) read_fields_.push_back(i);
  linear_ = LinearInParameters();
  if (linear_) summands_ = Summands();
}

// Parses the formula over this object's storage; throws InputError naming
// what is wrong with it.
void CompiledFormula::Validate() {
  const std::string where = "formula effect \"" + spec_.name + "\"";
  // Assignment would let a formula change its inputs: arithmetic only.
  if (std::regex_search(spec_.formula, std::regex(R"((^|[^=<>!])=($|[^=]))")))
    throw InputError(where + ": \"" + spec_.formula +
                     "\" assigns a value; a formula must be one arithmetic expression");
  std::string known;
  UnknownNames unknown;
  try {
    for (const auto& c : kCovariateFields) {
      parser_.DefineVar(c.name, &(covariates_.*c.field));
      known += std::string(known.empty() ? "" : ", ") + c.name;
    }
    for (std::size_t i = 0; i < spec_.parameters.size(); ++i) {
      for (const auto& c : kCovariateFields) {
        if (spec_.parameters[i].name == c.name)
          throw InputError(where + ": parameter \"" + c.name + "\" has a covariate's name; rename it");
      }
      parser_.DefineVar(spec_.parameters[i].name, &values_[i]);
      known += ", " + spec_.parameters[i].name;
    }
    parser_.SetVarFactory(RecordUnknown, &unknown);
    parser_.SetExpr(spec_.formula);
    parser_.GetUsedVar();
    parser_.Eval();
    if (parser_.GetNumResults() != 1) throw InputError(where + ": \"" + spec_.formula + "\" must be one expression");
  } catch (const mu::Parser::exception_type& e) {
    throw InputError(where + ": invalid formula \"" + spec_.formula + "\": " + e.GetMsg());
  }
  if (!unknown.names.empty()) {
    throw InputError(where + ": unknown variable \"" + *unknown.names.begin() + "\" in \"" + spec_.formula +
                     "\" (known: " + known + ")");
  }
  parser_.SetVarFactory(nullptr, nullptr);
}

std::size_t CompiledFormula::KeyHash::operator()(const Key& k) const {
  std::size_t h = 1469598103934665603ull;
  for (double v : k.values) h = (h ^ std::hash<double>{}(v)) * 1099511628211ull;
  return h;
}

// Each summand is evaluated at zero and once per parameter it holds (a sum
// of 60 one-parameter terms: 120 small evaluations, not 61 of the whole
// formula); every later evaluation of that sample, value or gradient, is a
// dot product. The terms depend on the covariates the formula reads and on
// no other: samples that differ elsewhere (the raw value, undistorted or
// not) share them.
const std::vector<double>* CompiledFormula::Terms(const Covariates& c, bool add) {
  if (!linear_) return nullptr;
  Key key;
  for (std::size_t i : read_fields_) key.values[i] = c.*kCovariateFields[i].field;
  {
    const std::shared_lock lock(terms_mutex_);
    if (const auto found = terms_.find(key); found != terms_.end()) return &found->second;
    if (!add || terms_.size() * (values_.size() + 1) > kMaxCachedTerms) return nullptr;
  }
  std::vector<double> terms(values_.size() + 1, 0.0);
  {
    const std::lock_guard lock(parse_mutex_);
    covariates_ = c;
    std::fill(values_.begin(), values_.end(), 0.0);
    for (const Summand& summand : summands_) {
      const double zero = summand.parser->Eval();
      terms[0] += zero;
      for (std::size_t i : summand.parameters) {
        values_[i] = 1;
        terms[i + 1] += summand.parser->Eval() - zero;
        values_[i] = 0;
      }
    }
  }
  const std::unique_lock lock(terms_mutex_);
  return &terms_.emplace(key, std::move(terms)).first->second;  // nodes never move: the pointer stays valid
}

// Whether the formula is linear in its parameters (k * x, a sum of terms
// each with one parameter as a factor): at 8 spread covariate values, the
// value at two random parameter vectors must equal the value at zero plus
// each parameter times its unit step's change, to 1e-9. A formula that is
// not (exp(-b * raw)) keeps central differences.
bool CompiledFormula::LinearInParameters() {
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

// The summands, each its own parser over the same storage with the
// parameters it reads, when at 8 drawn points their sum is the formula's
// value to 1e-12 relative; else the whole formula as one.
std::vector<CompiledFormula::Summand> CompiledFormula::Summands() {
  std::vector<Summand> out;
  try {
    for (const std::string& text : TopLevelSummands(spec_.formula)) {
      Summand summand{std::make_unique<mu::Parser>(), {}};
      Define(*summand.parser, covariates_, values_, text);
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
std::vector<CompiledFormula::Summand> CompiledFormula::WholeFormula() {
  Summand all{std::make_unique<mu::Parser>(), {}};
  Define(*all.parser, covariates_, values_, spec_.formula);
  for (std::size_t i = 0; i < values_.size(); ++i) all.parameters.push_back(i);
  std::vector<Summand> out;
  out.push_back(std::move(all));
  return out;
}

void CompiledFormula::Define(mu::Parser& parser, Covariates& covariates, std::vector<double>& values,
                             const std::string& text) const {
  for (const auto& c : kCovariateFields) parser.DefineVar(c.name, &(covariates.*c.field));
  for (std::size_t i = 0; i < spec_.parameters.size(); ++i) parser.DefineVar(spec_.parameters[i].name, &values[i]);
  parser.SetExpr(text);
  parser.Eval();
}

// Covariates spread over their usual ranges (kCovariateFields), for the numeric checks.
void CompiledFormula::DrawCovariates(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-1, 1);
  for (const auto& c : kCovariateFields) covariates_.*c.field = c.centre + c.spread * unit(rng);
}

}  // namespace speckle::model
