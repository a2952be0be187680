// The joint calibration's tests that take seconds: over twenty draws of its
// test rig, are its stated sigmas the scatter of its errors, neither smaller
// nor larger (one draw, joint_calibration_test.cc in the fast tier, cannot
// say)? And an effect the model lacks, against the same model with it.
// About 15 s in all, so they run in the full suite, not under the sanitizers.
#include <gtest/gtest.h>

#include "lab/joint/joint_test_rig.h"

namespace speckle::joint {
namespace {

using namespace testing;

TEST(JointCalibrationOverDraws, ItsStatedSigmasAreTheScatterOfItsErrors) {
  const Rig rig = TestRig();
  std::vector<double> errors;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    const Observations seen = Observe(rig, 20, rng);
    const auto fitted =
        RunJointCalibration({}, {rig.board, Start(rig), model::BaseForm::kReciprocal, {}, seen.frames, seen.samples});
    ASSERT_TRUE(Accepted(fitted)) << "seed " << seed << ": " << std::get<Rejection>(fitted).reason;
    const Score score = Scored(std::get<JointCalibration>(fitted), rig, seen);
    errors.insert(errors.end(), score.intrinsic_error_sigmas.begin(), score.intrinsic_error_sigmas.end());
    EXPECT_GE(score.share_within_3_sigma, 0.99) << "seed " << seed;
    EXPECT_LT(score.worst_depth_error, 5e-3) << "seed " << seed;
  }
  // 160 errors in sigmas: a normal draw has 0.4 beyond 3 (2 or fewer with
  // 99 % odds) and an RMS of 1 +- 0.056. Measured when written: none beyond
  // 3 and RMS 0.89; with the cluster-robust estimate alone, 16 draws had two
  // beyond 3 (colour cx at 4.6 and 4.0 sigma).
  int beyond = 0;
  double squares = 0;
  for (double z : errors) beyond += std::abs(z) > 3, squares += z * z;
  const double rms = std::sqrt(squares / static_cast<double>(errors.size()));
  EXPECT_LE(beyond, 2);
  EXPECT_GT(rms, 0.7) << "the sigmas overstate the errors";
  EXPECT_LT(rms, 1.2) << "the sigmas understate the errors";
}

// A tilt of the reference pattern (3 and -2 raw across the normalized
// image) that the model lacks: the cameras and poses take it up, 4.9-6.6
// sigma off and depth 0.7-1.3 % off over seeds 1-3. With reference_tilt in
// the problem they are within 2.8 sigma, depth within 0.33 %, and the tilt
// within 0.3 raw.
TEST(JointCalibrationWithEffects, AnEffectInTheModelIsFittedWithTheCamerasRatherThanTakenUpByThem) {
  Rig rig = TestRig();
  rig.tilt = {3.0, -2.0};
  std::mt19937 rng(3);
  const Observations seen = Observe(rig, 20, rng);
  const auto fit = [&](std::vector<model::EffectSpec> effects) {
    auto fitted = RunJointCalibration(
        {}, {rig.board, Start(rig), model::BaseForm::kReciprocal, {}, seen.frames, seen.samples, std::move(effects)});
    if (!Accepted(fitted)) throw std::runtime_error(std::get<Rejection>(fitted).reason);
    return std::get<JointCalibration>(std::move(fitted));
  };
  const auto worst_sigmas = [](const Score& s) {
    double worst = 0;
    for (double z : s.intrinsic_error_sigmas) worst = std::max(worst, std::abs(z));
    return worst;
  };
  const Score lacking = Scored(fit({}), rig, seen);
  EXPECT_GT(worst_sigmas(lacking), 3) << "without the effect the cameras should take it up (else this shows nothing)";
  EXPECT_GT(lacking.worst_depth_error, 5e-3);
  const JointCalibration with = fit({model::EffectSpec{"reference_tilt"}});
  const Score score = Scored(with, rig, seen);
  EXPECT_LT(worst_sigmas(score), 3);
  EXPECT_LT(score.worst_depth_error, 5e-3);
  EXPECT_GE(score.share_within_3_sigma, 0.99);
  ASSERT_EQ(with.effect_parameters.size(), 1u);
  ASSERT_EQ(with.effect_parameters[0].size(), 2u);
  EXPECT_NEAR(with.effect_parameters[0][0], rig.tilt[0], 0.5);
  EXPECT_NEAR(with.effect_parameters[0][1], rig.tilt[1], 0.5);
}

}  // namespace
}  // namespace speckle::joint
