// A camera the session gives with standard deviations is a prior of the
// joint calibration, not exact: a tight one holds the camera where the
// session put it, a loose one lets the observations move it to the truth,
// and a term given with sigma 0 is held at its value. A depth camera given
// keeps its focal lengths and lens; the depth image's principal point is fitted.
#include "lab/joint/camera_priors.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "lab/joint/joint_test_rig.h"

namespace speckle::joint {
namespace {

using testing::Observations;
using testing::Observe;
using testing::Rig;
using testing::Start;
using testing::TestRig;

// The colour camera as a session would give it: 1 % off in focal length and
// 3 px off in principal point, with `sigma` (fx fy cx cy k1 k2 p1 p2 k3).
CameraIntrinsics GivenColour(const Rig& rig, const std::array<double, 9>& sigma) {
  CameraIntrinsics c = rig.colour;
  c.camera_matrix(0, 0) *= 1.01, c.camera_matrix(1, 1) *= 1.01;
  c.camera_matrix(0, 2) += 3, c.camera_matrix(1, 2) -= 3;
  c.stddev = sigma;
  return c;
}

// The joint calibration of 20 poses of `rig` from `start`.
JointCalibration FitFrom(const Rig& rig, const CameraCalibration& start, int seed) {
  std::mt19937 rng(static_cast<unsigned>(seed));
  const Observations seen = Observe(rig, 20, rng);
  const auto fitted =
      RunJointCalibration({}, {rig.board, start, model::BaseForm::kReciprocal, {}, seen.frames, seen.samples});
  EXPECT_TRUE(Accepted(fitted)) << std::get<Rejection>(fitted).reason;
  return Accepted(fitted) ? std::get<JointCalibration>(fitted) : JointCalibration{};
}

JointCalibration FitWithColourPrior(const Rig& rig, const CameraIntrinsics& given, int seed) {
  CameraCalibration start = Start(rig);
  start.colour = given;  // as the camera step leaves a camera the session gave
  start.colour.rms_reprojection_px = 0.1;
  start.colour_prior = given;
  return FitFrom(rig, start, seed);
}

TEST(CameraPriors, ATightPriorHoldsTheColourCameraWhereTheSessionPutIt) {
  const Rig rig = TestRig();
  const CameraIntrinsics given = GivenColour(rig, {0.01, 0.01, 0.01, 0.01, 0.001, 0.001, 0, 0, 0});
  const JointCalibration j = FitWithColourPrior(rig, given, 11);
  EXPECT_NEAR(j.cameras.colour.camera_matrix(0, 0), given.camera_matrix(0, 0), 0.05);
  EXPECT_NEAR(j.cameras.colour.camera_matrix(0, 2), given.camera_matrix(0, 2), 0.05);
  EXPECT_GT(j.cameras.colour.stddev[0], 0);
  // About the prior's: the corners, 1 % from it, cannot tighten it, and
  // their conflict with it widens the cluster-robust sigma a little.
  EXPECT_NEAR(j.cameras.colour.stddev[0], 0.01, 0.001);
}

TEST(CameraPriors, ALoosePriorLetsTheCornersMoveTheColourCameraToTheTruth) {
  const Rig rig = TestRig();
  const CameraIntrinsics given = GivenColour(rig, {50, 50, 30, 30, 0.5, 0.5, 0, 0, 0});
  const JointCalibration j = FitWithColourPrior(rig, given, 12);
  const std::array<std::pair<int, int>, 4> at = {{{0, 0}, {1, 1}, {0, 2}, {1, 2}}};
  for (std::size_t i = 0; i < 4; ++i) {
    const auto [r, c] = at[i];
    const double error = j.cameras.colour.camera_matrix(r, c) - rig.colour.camera_matrix(r, c);
    EXPECT_LT(std::abs(error), 3 * j.cameras.colour.stddev[i]) << "intrinsic " << i;
    EXPECT_LT(std::abs(error), 1.5) << "intrinsic " << i << ": started 3-5 px off, the corners pin it";
    EXPECT_LT(j.cameras.colour.stddev[i], 2.0) << "intrinsic " << i;
  }
}

TEST(CameraPriors, ATermGivenWithSigmaZeroIsHeldAtItsValueAndNamed) {
  const Rig rig = TestRig();
  const CameraIntrinsics given = GivenColour(rig, {50, 50, 0, 0, 0.5, 0.5, 0, 0, 0});
  const JointCalibration j = FitWithColourPrior(rig, given, 13);
  EXPECT_EQ(j.cameras.colour.camera_matrix(0, 2), given.camera_matrix(0, 2));
  EXPECT_EQ(j.cameras.colour.camera_matrix(1, 2), given.camera_matrix(1, 2));
  EXPECT_NEAR(j.cameras.colour.camera_matrix(0, 0), rig.colour.camera_matrix(0, 0), 3.0)
      << "fx is free within its 50 px";
  ASSERT_TRUE(j.cameras.joint);
  const auto& held = j.cameras.joint->held;
  EXPECT_NE(std::find(held.begin(), held.end(), "colour cx (given exactly)"), held.end());
  EXPECT_NE(std::find(held.begin(), held.end(), "colour cy (given exactly)"), held.end());
}

// A depth camera the session gives is the IR image's: the depth image
// shifted 4 px, 3 px from it (as a Kinect's is) keeps the given focal
// lengths and lens, and its own principal point is fitted, exactly or
// within sigmas given alike.
JointCalibration FitWithShiftedDepthImage(const Rig& rig, const std::array<double, 9>& sigma, int seed) {
  CameraCalibration start = Start(rig);  // the depth image is observed through rig.depth
  start.depth = rig.depth;
  start.depth.camera_matrix(0, 2) += 4, start.depth.camera_matrix(1, 2) += 3;  // the IR image's
  start.depth.stddev = sigma;
  if (sigma[0] > 0) start.depth_prior = start.depth;
  return FitFrom(rig, start, seed);
}

TEST(CameraPriors, AGivenDepthCameraKeepsItsFocalLengthsAndTheDepthImagesPrincipalPointIsFitted) {
  const Rig rig = TestRig();
  for (const auto& sigma :
       {std::array<double, 9>{}, std::array<double, 9>{0.5, 0.5, 0.2, 0.2, 0.001, 0.001, 0, 0, 0}}) {
    const bool exact = sigma[0] == 0;
    const JointCalibration j = FitWithShiftedDepthImage(rig, sigma, exact ? 21 : 22);
    const CameraIntrinsics& d = j.cameras.depth;
    if (exact) EXPECT_EQ(d.camera_matrix(0, 0), rig.depth.camera_matrix(0, 0)) << "fx given exactly";
    EXPECT_NEAR(d.camera_matrix(0, 0), rig.depth.camera_matrix(0, 0), 3 * sigma[0] + 1e-9);
    for (int i : {2, 3}) {
      const double fitted = d.camera_matrix(i - 2, 2), truth = rig.depth.camera_matrix(i - 2, 2);
      EXPECT_GT(d.stddev[static_cast<std::size_t>(i)], 0) << "intrinsic " << i << (exact ? ", exact" : ", prior");
      EXPECT_LT(std::abs(fitted - truth), 3 * d.stddev[static_cast<std::size_t>(i)])
          << "intrinsic " << i << (exact ? ", exact" : ", prior") << ": " << fitted << " against " << truth;
    }
  }
}

}  // namespace
}  // namespace speckle::joint
