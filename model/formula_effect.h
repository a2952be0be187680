#pragma once
// An effect written in the model spec, no rebuild:
//   {"name": "raw_step", "doc": "...", "formula": "height * (raw > 700)",
//    "parameters": [{"name": "height", "unit": "raw", "initial": 0,
//                    "lower": -20, "upper": 20}]}
// The formula is arithmetic only (muparser: + - * / ^, comparisons, ?:, and
// functions such as exp, sqrt, abs, min, max) over the covariates (see
// covariates.h) and the effect's parameters. A formula linear in its
// parameters is evaluated once per sample, summand by summand, into a value
// and exact gradient that every later fit reuses; any other is
// differentiated numerically (central differences).
#include <nlohmann/json.hpp>

#include "model/effect.h"

namespace speckle::model {

// Formula effects fit between 1 and this many parameters (see FormulaSpecFromJson).
inline constexpr std::size_t kMaxFormulaParameters = 300;

struct FormulaSpec {
  std::string name, doc, formula;
  std::vector<EffectParameter> parameters;
};

// `where` names the spec in messages. Throws InputError.
FormulaSpec FormulaSpecFromJson(const nlohmann::json& json, const std::string& where);
nlohmann::json ToJson(const FormulaSpec& spec);

// Parses the formula; throws InputError for invalid formulas, unknown
// variables and anything but a single arithmetic expression.
std::unique_ptr<Effect> CreateFormulaEffect(const FormulaSpec& spec);

}  // namespace speckle::model
