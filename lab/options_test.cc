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
