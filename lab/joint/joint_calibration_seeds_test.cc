// The joint calibration over twenty draws of its test rig: are its stated
// sigmas the scatter of its errors, neither smaller nor larger? One draw
// (joint_calibration_test.cc, in the fast tier) cannot say; this takes about
// 15 s, so it runs in the full suite.
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

}  // namespace
}  // namespace speckle::joint
