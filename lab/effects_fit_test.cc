// The effect catalogue and formula effects as the fit uses them: each
// effect documented with sane parameters and exact gradients, formulas that
// fit like compiled effects and fail with clear errors.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <random>
#include <set>

#include "apps/model_summary.h"
#include "lab/diagnosis/model_diagnosis.h"
#include "lab/diagnosis/verdict.h"
#include "lab/diagnosis/verdict_text.h"
#include "lab/fit/tangent_form_manifold.h"
#include "lab/lab_test_samples.h"
#include "lab/model_spec.h"
#include "model/depth_model.h"
#include "model/formula_effect.h"
#include "schemas/errors.h"

namespace speckle {
namespace {

using nlohmann::json;

std::string ErrorOf(const json& spec) {
  try {
    ModelSpecFromJson(json{{"schema_version", 2}, {"effects", {spec}}}, "model.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(EffectCatalogue, EveryDomainEffectIsThereWithDocAndSaneParameters) {
  std::set<std::string> names;
  for (const auto& info : model::EffectCatalogue()) {
    names.insert(info.name);
    EXPECT_FALSE(info.doc.empty()) << info.name;
    const auto effect = info.create();
    EXPECT_FALSE(effect->CovariatesRead().empty()) << info.name;
    std::vector<double> initial;
    for (const auto& p : effect->Parameters()) {
      EXPECT_LE(p.lower, p.initial) << info.name << "." << p.name;
      EXPECT_LE(p.initial, p.upper) << info.name << "." << p.name;
      initial.push_back(p.initial);
    }
    model::Covariates c;
    c.raw = 800, c.u = 100, c.v = 400, c.x = -0.4, c.y = 0.3, c.time_s = 60, c.albedo = 0.2;
    EXPECT_TRUE(std::isfinite(effect->RawOffset(initial.data(), c))) << info.name;
  }
  for (const char* name : {"radial_billow", "disparity_pattern", "depth_grid_offset", "thermal_drift",
                           "capture_time_offset", "albedo_bias", "spatial_field"}) {
    EXPECT_TRUE(names.count(name)) << name;
  }
}

TEST(EffectCatalogue, GradientsMatchFiniteDifferences) {
  for (const auto& info : model::EffectCatalogue()) {
    const auto effect = info.create();
    std::vector<double> p;
    for (const auto& q : effect->Parameters())
      p.push_back(q.initial + 0.01 * (q.upper - q.lower > 1e6 ? 1 : q.upper - q.lower) * 0.3);
    // Move each B-spline control differently, so a gradient entry sent to the wrong control shows.
    for (std::size_t i = 0; i < p.size(); ++i) p[i] += 1e-3 * std::sin(1.0 + static_cast<double>(i));
    model::Covariates c;
    c.raw = 750, c.u = 610, c.v = 461, c.x = 0.3, c.y = -0.2, c.time_s = 100, c.gradient_u = 1.2, c.gradient_v = -0.7;
    c.velocity_u = 30, c.velocity_v = -10, c.albedo = 0.1, c.raw_rate = 25;
    std::vector<double> gradient(p.size(), std::nan(""));
    const double value = effect->RawOffset(p.data(), c, gradient.data());
    EXPECT_NEAR(value, effect->RawOffset(p.data(), c), 1e-9) << info.name;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double h = 1e-6 * std::max(1.0, std::abs(p[i]));
      std::vector<double> plus = p, minus = p;
      plus[i] += h, minus[i] -= h;
      const double numeric = (effect->RawOffset(plus.data(), c) - effect->RawOffset(minus.data(), c)) / (2 * h);
      EXPECT_NEAR(gradient[i], numeric, 1e-4 * std::max(1.0, std::abs(numeric))) << info.name << " parameter " << i;
    }
  }
}

TEST(FormulaEffect, FitsLikeTheCompiledOne) {
  const auto samples = Synthetic(4, [](const PairedSample& s) { return s.raw > 700 ? 2.0 : 0.0; });
  const json spec = {
      {"name", "raw_step"},
      {"formula", "height * (raw > 700)"},
      {"parameters", {{{"name", "height"}, {"unit", "raw"}, {"initial", 0}, {"lower", -20}, {"upper", 20}}}}};
  const DepthFit plain = Fit({model::BaseForm::kReciprocal, {}}, samples);
  const DepthFit stepped = Fit({model::BaseForm::kReciprocal, {model::EffectSpecFromJson(spec, "spec")}}, samples);
  EXPECT_LT(stepped.held_out_raw.rms, 0.8 * plain.held_out_raw.rms);
  EXPECT_NEAR(stepped.parameters[2], 2.0, 0.3);
  // The diagnosis of the plain model points along the raw value (or depth).
  const Diagnosis d = RunModelDiagnosis({}, samples, plain);
  const std::string top = d.covariates.front().covariate;
  EXPECT_TRUE(top == "raw" || top == "depth") << top << ": " << Words(d);
}

TEST(FormulaEffect, BadFormulasGiveClearErrors) {
  const json k = {{{"name", "k"}}};
  EXPECT_NE(ErrorOf({{"name", "e"}, {"formula", "k * (raw - "}, {"parameters", k}}).find("invalid formula"),
            std::string::npos);
  const std::string unknown = ErrorOf({{"name", "e"}, {"formula", "k * temperature"}, {"parameters", k}});
  EXPECT_NE(unknown.find("unknown variable \"temperature\""), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("model.json.effects[0]"), std::string::npos) << unknown;
  EXPECT_NE(ErrorOf({{"name", "e"}, {"formula", "raw = 3"}, {"parameters", k}}).find("assigns"), std::string::npos);
  EXPECT_NE(ErrorOf({{"name", "e"}, {"formula", "system(\"ls\")"}, {"parameters", k}}).find("invalid formula"),
            std::string::npos);
  EXPECT_NE(ErrorOf({{"name", "e"}, {"formula", "k"}, {"parameters", {{{"name", "raw"}}}}}).find("covariate's name"),
            std::string::npos);
  EXPECT_NE(ErrorOf("no_such_effect").find("unknown effect \"no_such_effect\""), std::string::npos);
  const std::string nul = ErrorOf({{"name", "e"}, {"formula", std::string("k * x\0 + k * y", 14)}, {"parameters", k}});
  EXPECT_NE(nul.find("formula: holds a NUL character at position 5"), std::string::npos) << nul;
  // Division by zero is caught before the fit, naming a sample.
  const auto samples = Synthetic(5, [](const PairedSample&) { return 0.0; });
  const json divide = {
      {"name", "e"}, {"formula", "k / (raw - raw)"}, {"parameters", {{{"name", "k"}, {"initial", 1}}}}};
  const auto fit =
      RunDepthModelFit({}, {model::BaseForm::kReciprocal, {model::EffectSpecFromJson(divide, "m")}}, samples);
  ASSERT_FALSE(Accepted(fit));
  EXPECT_NE(std::get<Rejection>(fit).reason.find("division by zero"), std::string::npos);
}

}  // namespace
}  // namespace speckle
