// The covariate table is what the verdict's words and hints come from: each
// axis reads real Covariates variables, and each hint is a formula effect
// the tool itself accepts (the user pastes it into a model spec).
#include "lab/diagnosis/covariate_axes.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "model/covariates.h"
#include "model/formula_effect.h"

namespace speckle {
namespace {

TEST(CovariateAxes, EachAxisIsShownByCovariatesThatExist) {
  std::set<std::string> variables;
  for (const auto& field : model::kCovariateFields) variables.insert(field.name);
  std::set<std::string> names;
  for (const auto& axis : CovariateAxes()) {
    EXPECT_TRUE(names.insert(axis.name).second) << "two axes named " << axis.name;
    EXPECT_FALSE(axis.shown_by.empty()) << axis.name;
    for (const auto& v : axis.shown_by) EXPECT_TRUE(variables.count(v)) << axis.name << " reads no variable " << v;
    EXPECT_EQ(FindCovariateAxis(axis.name), &axis);
  }
  EXPECT_EQ(FindCovariateAxis("no such axis"), nullptr);
}

TEST(CovariateAxes, EachHintIsAFormulaTheToolAccepts) {
  for (const auto& axis : CovariateAxes()) {
    std::string formula = axis.hint.formula;
    if (const auto at = formula.find("{level}"); at != std::string::npos) formula.replace(at, 7, "700");
    nlohmann::json spec = {{"name", axis.hint.name}, {"formula", formula}, {"parameters", nlohmann::json::array()}};
    for (const auto& [name, unit] : axis.hint.parameters)
      spec["parameters"].push_back({{"name", name}, {"unit", unit}});
    std::unique_ptr<model::Effect> effect;
    ASSERT_NO_THROW(effect = model::CreateFormulaEffect(model::FormulaSpecFromJson(spec, axis.name))) << spec.dump();
    EXPECT_EQ(effect->Parameters().size(), axis.hint.parameters.size()) << axis.name;
  }
}

}  // namespace
}  // namespace speckle
