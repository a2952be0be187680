// The lab's options check themselves: the defaults hold, and each broken
// rule is named by its field (a fit then says so instead of running).
#include <gtest/gtest.h>

#include <string>

#include "lab/diagnosis/diagnosis.h"
#include "lab/fit/depth_fit.h"

namespace speckle {
namespace {

TEST(LabOptions, DefaultsAreValid) {
  std::string why;
  EXPECT_TRUE(DepthFitOptions{}.IsValid(&why)) << why;
  EXPECT_TRUE(DiagnosisOptions{}.IsValid(&why)) << why;
}

TEST(LabOptions, EachBrokenRuleIsNamedByItsField) {
  DepthFitOptions fit;
  fit.max_iterations = 0;
  std::string why;
  EXPECT_FALSE(fit.IsValid(&why));
  EXPECT_NE(why.find("max_iterations"), std::string::npos) << why;
  fit = {};
  fit.huber_raw = -1;
  EXPECT_FALSE(fit.IsValid(&why));
  EXPECT_NE(why.find("huber_raw"), std::string::npos) << why;
  EXPECT_FALSE(fit.IsValid(nullptr));  // why is optional

  DiagnosisOptions diagnosis;
  diagnosis.max_p_value = 0;
  EXPECT_FALSE(diagnosis.IsValid(&why));
  EXPECT_NE(why.find("max_p_value"), std::string::npos) << why;
  diagnosis = {};
  diagnosis.max_neighbour_corner_px = diagnosis.min_neighbour_corner_px;
  EXPECT_FALSE(diagnosis.IsValid(&why));
  EXPECT_NE(why.find("max_neighbour_corner_px"), std::string::npos) << why;
  diagnosis = {};
  diagnosis.strong_reduction = 0.01;  // below min_reduction: the second tier would be the looser test
  EXPECT_FALSE(diagnosis.IsValid(&why));
  EXPECT_NE(why.find("strong_reduction"), std::string::npos) << why;
}

// The pose-level test's two tiers: a cut of 3 % at p <= 0.001, or a cut of
// half the held-out RMS at p <= 0.01 (an error that lies in a few poses).
TEST(LabOptions, ACutPassesThePoseTestAtTheStrictPOrAtTheLooserOneWhenItHalvesTheError) {
  const DiagnosisOptions d;
  EXPECT_TRUE(d.PassesPoseTest(0.04, 0.0009));
  EXPECT_FALSE(d.PassesPoseTest(0.02, 0.0001)) << "too small a cut";
  EXPECT_FALSE(d.PassesPoseTest(0.40, 0.005)) << "p above 0.001 with less than half cut";
  EXPECT_TRUE(d.PassesPoseTest(0.82, 0.0016)) << "tangent_base seed 6's";
  EXPECT_FALSE(d.PassesPoseTest(0.82, 0.02)) << "p above 0.01";
}

TEST(LabOptions, AFitWithInvalidOptionsIsNotFittedAndSaysWhy) {
  std::vector<PairedSample> samples(100);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    samples[i].raw = 600 + static_cast<double>(i);
    samples[i].depth_m = 1.0 + 0.01 * static_cast<double>(i);
    samples[i].pose = static_cast<int>(i % 5);
  }
  DepthFitOptions options;
  options.folds = -1;
  const auto fit = RunDepthModelFit(options, {model::BaseForm::kReciprocal, {}}, samples);
  ASSERT_FALSE(Accepted(fit));
  EXPECT_NE(std::get<Rejection>(fit).reason.find("invalid fit options: folds"), std::string::npos)
      << std::get<Rejection>(fit).reason;
}

}  // namespace
}  // namespace speckle
