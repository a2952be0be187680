#pragma once
// What every instance of one formula effect shares: the formula parsed and
// checked once, whether it is linear in its parameters, and for a linear one
// the terms of each sample seen so far. A fit makes a model (and so a formula
// effect) for each of its folds, camera refits and candidates, and reads
// models back hundreds of times: parsing a 60-term formula again each time
// was a tenth of a refit's CPU (bench/results/speed.md).
#include <muParser.h>

#include <array>
#include <memory>
#include <mutex>
#include <random>
#include <shared_mutex>
#include <unordered_map>
#include <vector>

#include "model/covariates.h"
#include "model/formula_effect.h"

namespace speckle::model {

class CompiledFormula {
 public:
  // The one compiled formula of this spec's formula and parameter names,
  // made on first use. Throws InputError for an invalid formula.
  static std::shared_ptr<CompiledFormula> Of(const FormulaSpec& spec);

  bool Linear() const { return linear_; }
  // The indices into kCovariateFields of the covariates the formula reads.
  const std::vector<std::size_t>& ReadFields() const { return read_fields_; }

  // For a linear formula: the offset at zero, then each parameter's term,
  // at c; computed once per distinct value of the covariates read and kept
  // (the pointer stays valid while this lives). Null when not linear, or
  // when the terms are not kept yet and `add` is false, or the cache is full.
  const std::vector<double>* Terms(const Covariates& c, bool add);

  // A parser of `text` (the formula or a part) over the caller's storage: an
  // instance's own evaluations, which would wait on the shared parsers' lock.
  void Define(mu::Parser& parser, Covariates& covariates, std::vector<double>& values, const std::string& text) const;
  const std::string& Formula() const { return spec_.formula; }

  explicit CompiledFormula(const FormulaSpec& spec);  // use Of()

 private:
  struct Summand {
    std::unique_ptr<mu::Parser> parser;
    std::vector<std::size_t> parameters;
  };
  struct Key {
    std::array<double, kCovariateFields.size()> values{};
    bool operator==(const Key& other) const { return values == other.values; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const;
  };
  static constexpr std::size_t kMaxCachedTerms = std::size_t{1} << 25;  // 256 MB of doubles

  void Validate();
  bool LinearInParameters();
  std::vector<Summand> Summands();
  std::vector<Summand> WholeFormula();
  void DrawCovariates(std::mt19937_64& rng);

  FormulaSpec spec_;
  bool linear_ = false;
  std::vector<std::size_t> read_fields_;
  // The shared parsers read these; evaluating them takes parse_mutex_.
  std::mutex parse_mutex_;
  Covariates covariates_;
  std::vector<double> values_;
  mu::Parser parser_;
  std::vector<Summand> summands_;  // when linear_
  std::shared_mutex terms_mutex_;
  std::unordered_map<Key, std::vector<double>, KeyHash> terms_;
};

}  // namespace speckle::model
