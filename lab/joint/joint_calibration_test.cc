// The joint calibration on observations made here from a known rig: what
// it recovers from cameras started pixels and percent away, and whether its
// stated uncertainty holds the truth; the cluster-robust covariance against
// the scatter of repeated fits.
#include "lab/joint/joint_calibration.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <random>

#include "lab/joint/cluster_covariance.h"
#include "lab/joint/joint_residuals.h"
#include "stages/outline_calibration.h"

namespace speckle::joint {
namespace {

// y = a + b x, each cluster of points offset alike: the fit's a scatters by
// the offsets' spread over the clusters, whatever the number of points.
struct Line {
  double x, y;
  template <typename T>
  bool operator()(const T* p, T* r) const {
    r[0] = T(y) - p[0] - p[1] * T(x);
    return true;
  }
};

TEST(ClusterRobustCovariance, StatesTheScatterOfFitsWhoseErrorsAreSharedWithinClusters) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 0.1), offset(0, 1.0);
  std::uniform_real_distribution<double> where(-1, 1);
  std::vector<double> fitted, robust_sigma, naive_sigma;
  for (int draw = 0; draw < 200; ++draw) {
    double p[2] = {0, 0};
    ceres::Problem problem;
    std::vector<ceres::ResidualBlockId> ids;
    std::vector<int> cluster;
    for (int c = 0; c < 20; ++c) {
      const double shared = offset(rng);
      for (int i = 0; i < 30; ++i) {
        const double x = where(rng);
        ids.push_back(problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<Line, 1, 2>(new Line{x, 2 + 0.5 * x + shared + noise(rng)}), nullptr, p));
        cluster.push_back(c);
      }
    }
    ceres::Solver::Summary summary;
    ceres::Solver::Options options;
    ceres::Solve(options, &problem, &summary);
    const auto robust = ClusterRobustCovariance(problem, ids, cluster, {p});
    ASSERT_TRUE(robust);
    fitted.push_back(p[0]);
    robust_sigma.push_back(std::sqrt((*robust)(0, 0)));
    // Counted as independent: the residual variance over the Hessian.
    double squares = 0;
    for (std::size_t i = 0; i < ids.size(); ++i) {
      double cost = 0, r = 0;
      problem.EvaluateResidualBlock(ids[i], false, &cost, &r, nullptr);
      squares += r * r;
    }
    naive_sigma.push_back(std::sqrt(squares / static_cast<double>(ids.size() - 2) / static_cast<double>(ids.size())));
  }
  double mean = 0, spread = 0, robust = 0, naive = 0;
  for (double a : fitted) mean += a / fitted.size();
  for (double a : fitted) spread += (a - mean) * (a - mean) / (fitted.size() - 1);
  spread = std::sqrt(spread);
  for (std::size_t i = 0; i < fitted.size(); ++i)
    robust += robust_sigma[i] / fitted.size(), naive += naive_sigma[i] / fitted.size();
  EXPECT_NEAR(robust / spread, 1.0, 0.25) << "robust " << robust << ", scatter of the fits " << spread;
  EXPECT_LT(naive / spread, 0.3) << "the independent count should understate it (else this test shows nothing)";
}

// A rig, its boards and what each camera sees of them.
struct Rig {
  CameraIntrinsics colour, depth;
  Eigen::Isometry3d depth_from_colour = Eigen::Isometry3d::Identity();
  std::vector<double> base = {-0.0030, 3.3};  // reciprocal: z = 1 / (a raw + b)
  BoardGeometry board{9, 7, 0.04};
};

CameraIntrinsics Camera(double fx, double fy, double cx, double cy, std::array<double, 5> lens) {
  CameraIntrinsics c;
  c.image_size = {640, 480};
  c.camera_matrix = cv::Matx33d(fx, 0, cx, 0, fy, cy, 0, 0, 1);
  c.distortion = lens;
  return c;
}

Eigen::Vector2d Projected(const CameraIntrinsics& c, const Eigen::Vector3d& q) {
  double k[4], lens[5], pixel[2];
  const cv::Matx33d& m = c.camera_matrix;
  k[0] = m(0, 0), k[1] = m(1, 1), k[2] = m(0, 2), k[3] = m(1, 2);
  std::copy(c.distortion.begin(), c.distortion.end(), lens);
  Project(k, lens, q.data(), pixel);
  return {pixel[0], pixel[1]};
}

struct Observations {
  std::vector<BoardFrame> frames;
  std::vector<PairedSample> samples;
  std::vector<double> true_depths;
};

Observations Observe(const Rig& rig, int poses, std::mt19937& rng) {
  std::normal_distribution<double> pixel_noise(0, 0.1), raw_noise(0, 0.3);
  std::uniform_real_distribution<double> depth(0.7, 2.6), tilt(-0.5, 0.5), lateral(-0.25, 0.25);
  Observations out;
  const auto outline = OutlineCorners(rig.board);
  for (int f = 0; f < poses; ++f) {
    BoardFrame frame;
    frame.frame = f, frame.pose = f;
    const double z = depth(rng);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = (Eigen::AngleAxisd(tilt(rng), Eigen::Vector3d::UnitX()) *
                     Eigen::AngleAxisd(tilt(rng), Eigen::Vector3d::UnitY()))
                        .toRotationMatrix();
    const Eigen::Vector3d centre(rig.board.Width() / 2, rig.board.Height() / 2, 0);
    pose.translation() = Eigen::Vector3d(lateral(rng) * z, lateral(rng) * z, z) - pose.linear() * centre;
    frame.colour_from_board = pose;
    for (const auto& p : rig.board.InteriorCornerPoints()) {
      const Eigen::Vector2d px = Projected(rig.colour, pose * Eigen::Vector3d(p.x, p.y, p.z));
      frame.colour_corners.emplace_back(px.x() + pixel_noise(rng), px.y() + pixel_noise(rng));
    }
    DepthboardQuad quad;
    for (int c = 0; c < 4; ++c)
      quad.corners_px[static_cast<std::size_t>(c)] =
          Projected(rig.depth, rig.depth_from_colour * pose * outline[static_cast<std::size_t>(c)]) +
          Eigen::Vector2d(pixel_noise(rng), pixel_noise(rng));
    frame.quad = quad;
    for (int i = 1; i < 10; ++i)
      for (int j = 1; j < 8; ++j) {
        const Eigen::Vector3d in_depth =
            rig.depth_from_colour * pose * Eigen::Vector3d(rig.board.Width() * i / 10, rig.board.Height() * j / 8, 0);
        const Eigen::Vector2d px = Projected(rig.depth, in_depth);
        PairedSample s;
        s.frame = f, s.pose = f, s.u = px.x(), s.v = px.y();
        s.raw = model::RawFromDepth(model::BaseForm::kReciprocal, rig.base.data(), in_depth.z()) + raw_noise(rng);
        out.samples.push_back(s);
        out.true_depths.push_back(in_depth.z());
      }
    out.frames.push_back(frame);
  }
  return out;
}

// Started where a user's separate steps leave it: the colour focal length
// 0.8 % off, the depth camera 2 % and 6 px off, the extrinsics 4 mm off
// along the axis. Each term started with a standard deviation is freed.
CameraCalibration Start(const Rig& rig) {
  CameraCalibration c;
  c.colour = Camera(rig.colour.camera_matrix(0, 0) * 1.008, rig.colour.camera_matrix(1, 1) * 1.008,
                    rig.colour.camera_matrix(0, 2) + 2, rig.colour.camera_matrix(1, 2) - 2, {0, 0, 0, 0, 0});
  c.depth = Camera(rig.depth.camera_matrix(0, 0) * 0.98, rig.depth.camera_matrix(1, 1) * 0.98,
                   rig.depth.camera_matrix(0, 2) + 6, rig.depth.camera_matrix(1, 2) - 4, {0, 0, 0, 0, 0});
  c.colour.stddev = c.depth.stddev = {1, 1, 1, 1, 0.01, 0.01, 0, 0, 0};
  c.colour.rms_reprojection_px = 0.1;
  c.depth_from_colour = rig.depth_from_colour;
  c.depth_from_colour.translation().z() += 0.004;
  c.extrinsics_rms_px = 0.1;
  return c;
}

Rig TestRig() {
  Rig rig;
  rig.colour = Camera(525, 524, 318, 243, {0.12, -0.25, 0, 0, 0});
  rig.depth = Camera(588.9, 587.5, 321.4, 252.1, {-0.08, 0.15, 0, 0, 0});
  rig.depth_from_colour.translation() = Eigen::Vector3d(-0.025, 0.001, 0.002);
  rig.depth_from_colour.linear() =
      Eigen::AngleAxisd(0.01, Eigen::Vector3d(0.3, 1, 0.1).normalized()).toRotationMatrix();
  return rig;
}

TEST(JointCalibration, RecoversBothCamerasFromStartsPercentOffWithinItsStatedUncertainty) {
  const Rig rig = TestRig();
  std::mt19937 rng(3);
  const Observations seen = Observe(rig, 20, rng);
  const CameraCalibration start = Start(rig);
  const auto fitted =
      RunJointCalibration({}, {rig.board, start, model::BaseForm::kReciprocal, {}, seen.frames, seen.samples});
  ASSERT_TRUE(Accepted(fitted)) << std::get<Rejection>(fitted).reason;
  const JointCalibration& j = std::get<JointCalibration>(fitted);
  const auto expect_within = [](const CameraIntrinsics& got, const CameraIntrinsics& truth, const char* camera) {
    const double values[4] = {got.camera_matrix(0, 0), got.camera_matrix(1, 1), got.camera_matrix(0, 2),
                              got.camera_matrix(1, 2)};
    const double expected[4] = {truth.camera_matrix(0, 0), truth.camera_matrix(1, 1), truth.camera_matrix(0, 2),
                                truth.camera_matrix(1, 2)};
    for (int i = 0; i < 4; ++i) {
      const double sigma = got.stddev[static_cast<std::size_t>(i)];
      EXPECT_GT(sigma, 0) << camera << " " << i;
      EXPECT_LT(sigma, 1.0) << camera << " " << i << ": 20 poses pin it to well under a pixel";
      EXPECT_NEAR(values[i], expected[i], 3 * sigma) << camera << " " << i;
    }
  };
  expect_within(j.cameras.colour, rig.colour, "colour");
  expect_within(j.cameras.depth, rig.depth, "depth");
  EXPECT_NEAR(j.cameras.depth_from_colour.translation().z(), rig.depth_from_colour.translation().z(),
              3 * j.cameras.extrinsics_translation_sigma_m.z());
  // Every sample's depth on its plane: within 0.2 % of the truth where the
  // start was 2 % off, and within 3 of its stated sigmas (the directions'
  // and its own pose's).
  double worst = 0;
  int within = 0;
  for (std::size_t i = 0; i < seen.samples.size(); ++i) {
    const double error = j.depths[i] - seen.true_depths[i];
    double variance = j.residual_sigma_m[i] * j.residual_sigma_m[i];
    for (const auto& moved : j.perturbations) variance += std::pow(moved[i] - j.depths[i], 2);
    within += std::abs(error) <= 3 * std::sqrt(variance);
    worst = std::max(worst, std::abs(error) / seen.true_depths[i]);
  }
  EXPECT_LT(worst, 2e-3);
  EXPECT_GE(within, 0.99 * static_cast<double>(seen.samples.size()));
  ASSERT_TRUE(j.cameras.joint);
  EXPECT_EQ(j.cameras.joint->terms.size(), 3u);
  EXPECT_FALSE(j.perturbations.empty());
}

TEST(JointCalibration, TooFewFramesWithBothCamerasAreRefusedSayingHowMany) {
  const Rig rig = TestRig();
  std::mt19937 rng(4);
  Observations seen = Observe(rig, 2, rng);
  const auto fitted =
      RunJointCalibration({}, {rig.board, Start(rig), model::BaseForm::kReciprocal, {}, seen.frames, seen.samples});
  ASSERT_FALSE(Accepted(fitted));
  EXPECT_NE(std::get<Rejection>(fitted).reason.find("2 board frames"), std::string::npos)
      << std::get<Rejection>(fitted).reason;
}

}  // namespace
}  // namespace speckle::joint
