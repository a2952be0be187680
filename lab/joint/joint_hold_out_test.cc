// A candidate judged inside the joint problem: a reference tilt the model
// lacks is taken up by the cameras and poses when the base form alone is
// fitted jointly, yet held out by pose the tilt still predicts the depths
// better; on a rig without it, the tilt gains nothing.
#include "lab/joint/joint_hold_out.h"

#include <gtest/gtest.h>

#include <map>
#include <random>

#include "lab/joint/joint_test_rig.h"
#include "lab/stats/residual_stats.h"

namespace speckle::joint {
namespace {

using testing::Observations;
using testing::Observe;
using testing::Rig;
using testing::Start;
using testing::TestRig;

struct Judged {
  double without_rms = 0, with_rms = 0;
  double without_prediction_sigma = 0;  // RMS over the held-out samples (raw)
  int poses_better = 0, poses = 0;
};

// The base form alone fitted jointly (the cameras the judge starts from),
// then the current model and the model with reference_tilt held out by pose.
Judged JudgeTilt(const Rig& rig, unsigned seed) {
  std::mt19937 rng(seed);
  const Observations seen = Observe(rig, 20, rng);
  const auto joint =
      RunJointCalibration({}, {rig.board, Start(rig), model::BaseForm::kReciprocal, {}, seen.frames, seen.samples});
  if (!Accepted(joint)) throw std::runtime_error(std::get<Rejection>(joint).reason);
  const CameraCalibration& cameras = std::get<JointCalibration>(joint).cameras;
  const auto held_out = [&](std::vector<model::EffectSpec> effects) {
    auto r = HoldOutPosesJointly(
        {}, {rig.board, cameras, model::BaseForm::kReciprocal, {}, seen.frames, seen.samples, std::move(effects)}, 5);
    if (!Accepted(r)) throw std::runtime_error(std::get<Rejection>(r).reason);
    return std::get<HeldOutFit>(std::move(r));
  };
  const HeldOutFit without = held_out({}), with = held_out({model::EffectSpec{"reference_tilt"}});
  Judged out{without.held_out_raw.rms, with.held_out_raw.rms, Summarize(without.held_out_prediction_sigma_raw).rms};
  std::map<int, std::pair<double, double>> squares;
  for (std::size_t i = 0; i < seen.samples.size(); ++i) {
    const double a = without.held_out_residual_raw[i], b = with.held_out_residual_raw[i];
    if (!std::isfinite(a) || !std::isfinite(b)) continue;
    squares[seen.samples[i].pose].first += a * a;
    squares[seen.samples[i].pose].second += b * b;
  }
  for (const auto& [pose, sq] : squares) out.poses_better += sq.second < sq.first;
  out.poses = static_cast<int>(squares.size());
  return out;
}

TEST(JointHoldOut, AnEffectTheCamerasTookUpStillPredictsHeldOutPosesBetter) {
  Rig rig = TestRig();
  rig.tilt = {3.0, -2.0};
  const Judged j = JudgeTilt(rig, 3);
  EXPECT_EQ(j.poses, 20);
  EXPECT_LT(j.with_rms, 0.8 * j.without_rms) << j.with_rms << " against " << j.without_rms;
  EXPECT_GE(j.poses_better, 17);
}

// ... and its held-out error is what the raw noise (0.3) and each
// prediction's stated sigma add up to: the floor the diagnosis compares with.
TEST(JointHoldOut, OnARigWithoutTheEffectItGainsNothing) {
  const Judged j = JudgeTilt(TestRig(), 3);
  EXPECT_GT(j.with_rms, 0.97 * j.without_rms) << j.with_rms << " against " << j.without_rms;
  EXPECT_GT(j.without_prediction_sigma, 0.02);
  EXPECT_NEAR(j.without_rms / std::hypot(0.3, j.without_prediction_sigma), 1.0, 0.1)
      << j.without_rms << " held out against the prediction's sigma " << j.without_prediction_sigma;
}

TEST(JointHoldOut, CamerasThatAreNotAJointCalibrationsAreRefused) {
  const Rig rig = TestRig();
  std::mt19937 rng(3);
  const Observations seen = Observe(rig, 5, rng);
  const auto r =
      HoldOutPosesJointly({}, {rig.board, Start(rig), model::BaseForm::kReciprocal, {}, seen.frames, seen.samples}, 5);
  ASSERT_FALSE(Accepted(r));
  EXPECT_NE(std::get<Rejection>(r).reason.find("not a joint calibration"), std::string::npos);
}

}  // namespace
}  // namespace speckle::joint
