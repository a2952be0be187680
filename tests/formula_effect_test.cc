// A formula effect's value and parameter gradient against the same formula
// written out in C++: through the linear path (each top-level summand
// evaluated on its own, the terms cached per sample), through its fallback
// when the summands do not add up to the formula (a ternary), and through
// central differences when the formula is not linear in its parameters.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <thread>

#include "model/covariates.h"
#include "model/formula_effect.h"
#include "schemas/errors.h"

namespace speckle::model {
namespace {

struct Case {
  std::string formula;
  std::vector<std::string> parameters;
  std::function<double(const std::vector<double>&, const Covariates&)> written_out;
};

FormulaSpec SpecOf(const Case& c) {
  FormulaSpec spec;
  spec.name = "e";
  spec.formula = c.formula;
  for (const auto& name : c.parameters) spec.parameters.push_back({name, "raw", 0, -1e30, 1e30});
  return spec;
}

TEST(FormulaEffect, ValueAndGradientAreTheFormulasWhicheverWayItIsEvaluated) {
  const double pi = 3.14159265358979323846;
  const std::vector<Case> cases = {
      // Linear, split into summands; an exponent's sign is not a summand's.
      {"a * cos(2 * _pi * u / 640) + b * 1e-3 * v - c * x + 0.25",
       {"a", "b", "c"},
       [&](const auto& p, const Covariates& c) {
         return p[0] * std::cos(2 * pi * c.u / 640) + p[1] * 1e-3 * c.v - p[2] * c.x + 0.25;
       }},
      {"-a*y+b*(raw-700)*2e+2-a*(u>300)",
       {"a", "b"},
       [](const auto& p, const Covariates& c) {
         return -p[0] * c.y + p[1] * (c.raw - 700) * 2e+2 - p[0] * (c.u > 300 ? 1.0 : 0.0);
       }},
      // Linear, but '?:' binds looser than '+': the summands do not add up
      // to the formula, and the whole formula is evaluated instead.
      {"x > 0 ? a * u : b + c * v",
       {"a", "b", "c"},
       [](const auto& p, const Covariates& c) { return c.x > 0 ? p[0] * c.u : p[1] + p[2] * c.v; }},
      // Not linear: central differences.
      {"a * exp(-b * raw / 1000)",
       {"a", "b"},
       [](const auto& p, const Covariates& c) { return p[0] * std::exp(-p[1] * c.raw / 1000); }},
  };
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (const Case& k : cases) {
    const auto effect = CreateFormulaEffect(SpecOf(k));
    for (int draw = 0; draw < 20; ++draw) {
      Covariates c;
      c.u = 320 + 300 * unit(rng), c.v = 240 + 220 * unit(rng), c.x = 0.5 * unit(rng), c.y = 0.4 * unit(rng);
      std::vector<double> p(k.parameters.size());
      for (double& v : p) v = 2 * unit(rng);
      // The same pixel at two raw values: a formula that reads raw must not
      // share the terms of another raw value; one that does not may.
      for (double raw : {650.0, 900.0}) {
        c.raw = raw;
        std::vector<double> gradient(p.size());
        const double value = effect->RawOffset(p.data(), c, gradient.data());
        const double expected = k.written_out(p, c);
        ASSERT_NEAR(value, expected, 1e-9 * std::max(1.0, std::abs(expected))) << k.formula;
        ASSERT_NEAR(effect->RawOffset(p.data(), c), expected, 1e-9 * std::max(1.0, std::abs(expected))) << k.formula;
        for (std::size_t i = 0; i < p.size(); ++i) {
          std::vector<double> plus = p, minus = p;
          plus[i] += 1e-5, minus[i] -= 1e-5;
          const double slope = (k.written_out(plus, c) - k.written_out(minus, c)) / 2e-5;
          EXPECT_NEAR(gradient[i], slope, 1e-5 * std::max(1.0, std::abs(slope)))
              << k.formula << " d/d" << k.parameters[i];
        }
      }
    }
  }
}

// A fit reads a linear formula's terms once per sample (Effect::LinearTerms):
// they must give the offset and gradient, and a formula that is not linear
// must give none.
TEST(FormulaEffect, LinearTermsGiveTheOffsetAndNoneWhenNotLinear) {
  const Case linear{"a * cos(2 * _pi * u / 640) + b * v - 3", {"a", "b"}, nullptr};
  const auto effect = CreateFormulaEffect(SpecOf(linear));
  Covariates c;
  c.u = 100, c.v = 50;
  const double* terms = effect->LinearTerms(c);
  ASSERT_NE(terms, nullptr);
  const double p[2] = {0.7, -0.2};
  EXPECT_NEAR(terms[0] + terms[1] * p[0] + terms[2] * p[1], effect->RawOffset(p, c), 1e-12);
  EXPECT_NEAR(terms[1], std::cos(2 * 3.14159265358979323846 * 100 / 640), 1e-12);
  EXPECT_NEAR(terms[2], 50, 1e-12);
  const Case curved{"a * exp(-b * raw / 1000)", {"a", "b"}, nullptr};
  EXPECT_EQ(CreateFormulaEffect(SpecOf(curved))->LinearTerms(c), nullptr);
}

// Instances of one formula share its parse and its terms (CompiledFormula);
// fits run side by side, each with its own instance, so two threads
// evaluating new samples at once must each get the formula's values.
TEST(FormulaEffect, InstancesOfOneFormulaEvaluateSideBySide) {
  const Case k{"a * u + b * v * v + (x > 0 ? c : 0)", {"a", "b", "c"}, nullptr};
  const auto check = [&](int seed, int* wrong) {
    const auto effect = CreateFormulaEffect(SpecOf(k));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-1, 1);
    for (int i = 0; i < 20000; ++i) {
      Covariates c;
      c.u = 640 * unit(rng), c.v = 480 * unit(rng), c.x = unit(rng);
      const double p[3] = {unit(rng), unit(rng), unit(rng)};
      double gradient[3];
      const double value = effect->RawOffset(p, c, gradient);
      const double expected = p[0] * c.u + p[1] * c.v * c.v + (c.x > 0 ? p[2] : 0);
      *wrong += std::abs(value - expected) > 1e-9 * std::max(1.0, std::abs(expected));
    }
  };
  int wrong[2] = {0, 0};
  std::thread first(check, 1, &wrong[0]), second(check, 2, &wrong[1]);
  first.join(), second.join();
  EXPECT_EQ(wrong[0] + wrong[1], 0);
}

// Issue 47's outside probe: two parameters of one name were fitted as two
// (one "not identified"), and a formula named like a catalogue effect made a
// version that read as holding it.
TEST(FormulaEffect, ARepeatedParameterNameOrACatalogueEffectsNameIsRefused) {
  const auto refused = [](const nlohmann::json& json, const std::string& named) {
    try {
      FormulaSpecFromJson(json, "model.json: effects[0]");
      ADD_FAILURE() << json.dump() << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
  };
  refused({{"name", "e"}, {"formula", "height * x"}, {"parameters", {{{"name", "height"}}, {{"name", "height"}}}}},
          "model.json: effects[0].parameters[1].name: \"height\" names an earlier parameter too");
  refused({{"name", "thermal_drift"}, {"formula", "k * x"}, {"parameters", {{{"name", "k"}}}}},
          "model.json: effects[0].name: \"thermal_drift\" is a catalogue effect's name");
  EXPECT_NO_THROW(
      FormulaSpecFromJson({{"name", "e"}, {"formula", "k * x"}, {"parameters", {{{"name", "k"}}}}}, "model.json"));
}

}  // namespace
}  // namespace speckle::model
