// The depth camera fitted with the extrinsics from depthboard outlines
// (RunDepthCameraFromOutlines), on outlines projected through a known rig:
// from the nominal camera it finds the true one within its own sigmas, and
// an IR chessboard's calibration given as a prior (ExtrinsicsOptions::
// depth_prior) holds it as tightly as that calibration's sigmas say, and no
// tighter. Its covariance is taken on a scaled Jacobian (ScaledCovariance),
// which a problem whose columns span ten orders does not fool.
#include <gtest/gtest.h>

#include <random>

#include "model/base_form.h"
#include "stages/outline_calibration.h"
#include "stages/scaled_covariance.h"
#include "synthetic_views.h"

namespace speckle {
namespace {

const BoardGeometry kBoard{11, 8, 0.0223};
const CameraIntrinsics kDepth = synthetic::Camera(588.9, 586.2, 316.8, 252.1, {-0.11, 0.48, 0, 0, 0});
constexpr double kCornerSigmaPx = 0.1;

Eigen::Isometry3d TrueDepthFromColour() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(0.006, Eigen::Vector3d::UnitX()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(-0.0252, 0.0011, 0.0018);
  return t;
}

// Still boards, their outline corners through the true rig plus noise.
std::vector<ExtrinsicsView> StillViews(int n, std::mt19937& rng) {
  std::normal_distribution<double> noise(0, kCornerSigmaPx);
  std::vector<ExtrinsicsView> views;
  const auto outline = OutlineCorners(kBoard);
  for (const auto& pose : synthetic::SpreadPoses(kBoard, n, rng, 0.6, 1.8)) {
    ExtrinsicsView v;
    v.colour_from_board = pose;
    for (int k = 0; k < 4; ++k)
      v.quad.corners_px[k] =
          kDepth.Project(TrueDepthFromColour() * (pose * outline[k])) + Eigen::Vector2d(noise(rng), noise(rng));
    views.push_back(v);
  }
  return views;
}

TEST(DepthCameraFromOutlines, FindsTheTrueCameraFromNominalAndAPriorHoldsItByItsSigmas) {
  std::mt19937 rng(3);
  const std::vector<ExtrinsicsView> views = StillViews(40, rng);
  const CameraIntrinsics nominal = synthetic::Camera(580, 580, 319.5, 239.5);
  ExtrinsicsOptions options;
  auto free =
      RunDepthCameraFromOutlines(options, DepthReading{}, kBoard, nominal, views, synthetic::NominalDepthFromColour());
  ASSERT_TRUE(Accepted(free)) << std::get<Rejection>(free).reason;
  const CameraIntrinsics& found = *std::get<ExtrinsicsResult>(free).depth;
  const double truth[4] = {588.9, 586.2, 316.8, 252.1};
  const double fitted[4] = {found.camera_matrix(0, 0), found.camera_matrix(1, 1), found.camera_matrix(0, 2),
                            found.camera_matrix(1, 2)};
  for (int i = 0; i < 4; ++i) {
    ASSERT_GT(found.stddev[static_cast<std::size_t>(i)], 0) << i;
    EXPECT_LT(std::abs(fitted[i] - truth[i]), 4 * found.stddev[static_cast<std::size_t>(i)])
        << i << ": " << fitted[i] << " vs " << truth[i] << " sigma " << found.stddev[static_cast<std::size_t>(i)];
  }

  // An IR calibration 6 px off in cx. Told to 0.05 px, it holds the fit
  // there; told to 50 px, the outlines move it back to the truth.
  CameraIntrinsics ir = kDepth;
  ir.camera_matrix(0, 2) += 6;
  for (const auto& [sigma_cx, expect_near] : {std::pair{0.05, 316.8 + 6}, std::pair{50.0, 316.8}}) {
    ir.stddev = {0.5, 0.5, sigma_cx, 0.5, 0.005, 0.02, 0, 0, 0};
    options.depth_prior = ir;
    auto held =
        RunDepthCameraFromOutlines(options, DepthReading{}, kBoard, ir, views, synthetic::NominalDepthFromColour());
    ASSERT_TRUE(Accepted(held)) << std::get<Rejection>(held).reason;
    const CameraIntrinsics& c = *std::get<ExtrinsicsResult>(held).depth;
    const double tolerance = std::max(0.25, 4 * found.stddev[2]);
    EXPECT_NEAR(c.camera_matrix(0, 2), expect_near, sigma_cx < 1 ? 0.25 : tolerance) << "prior sigma " << sigma_cx;
    // A term the IR calibration held (sigma 0: p1, p2, k3) stays where it was.
    EXPECT_NEAR(c.distortion[4], 0, 1e-6) << "prior sigma " << sigma_cx;
    // The prior's information is in the sigma too.
    if (sigma_cx < 1) EXPECT_LT(c.stddev[2], 0.06) << c.stddev[2];
  }
}

// A wide-angle adapter billows the raw values towards the image's edge
// (thesis Eq. 4.2): tens of raw units on a near board's corners. The board
// planes pin the lens terms only if the fit knows that; otherwise they took
// the billowing up as distortion (a room session: k1 -0.06 +- 0.86 where it
// was -0.23, fx 373 +- 7 where it was 379).
TEST(DepthCameraFromOutlines, BillowedBoardPlanesDoNotBendTheLens) {
  const CameraIntrinsics wide = synthetic::Camera(379.1, 378.5, 312.2, 234.3, {-0.234, 0.103, -0.006, 0.002, -0.035});
  const double base[2] = {-0.0041952, 4.5380}, bx = 120000, by = 50000;
  std::mt19937 rng(5);
  std::normal_distribution<double> corner_noise(0, kCornerSigmaPx), raw_noise(0, 0.6);
  const auto outline = OutlineCorners(kBoard);
  std::vector<ExtrinsicsView> views;
  std::vector<Eigen::Vector3d> seen;  // the board points, in the depth camera
  for (const auto& pose : synthetic::SpreadPoses(kBoard, 24, rng, 0.4, 1.2)) {
    ExtrinsicsView v;
    v.colour_from_board = pose;
    for (int k = 0; k < 4; ++k)
      v.quad.corners_px[k] = wide.Project(TrueDepthFromColour() * (pose * outline[k])) +
                             Eigen::Vector2d(corner_noise(rng), corner_noise(rng));
    // Board pixels on a 1 cm grid over the board.
    for (double along_m = 0.005; along_m < kBoard.Width(); along_m += 0.01) {
      for (double down_m = 0.005; down_m < kBoard.Height(); down_m += 0.01) {
        const Eigen::Vector3d in_depth = TrueDepthFromColour() * (pose * Eigen::Vector3d(along_m, down_m, 0));
        seen.push_back(in_depth);
        const double x = in_depth.x() / in_depth.z(), y = in_depth.y() / in_depth.z();
        const double raw = model::RawFromDepth(model::BaseForm::kReciprocal, base, in_depth.z());
        const Eigen::Vector2d pixel = wide.Project(in_depth);
        v.board_pixels.emplace_back(pixel.x(), pixel.y(),
                                    std::sqrt(raw * raw + bx * x * x + by * y * y) + raw_noise(rng));
      }
    }
    views.push_back(v);
  }
  auto fitted = RunDepthCameraFromOutlines({}, DepthReading{}, kBoard, synthetic::Camera(580, 580, 319.5, 239.5), views,
                                           synthetic::NominalDepthFromColour());
  ASSERT_TRUE(Accepted(fitted)) << std::get<Rejection>(fitted).reason;
  const CameraIntrinsics& found = *std::get<ExtrinsicsResult>(fitted).depth;
  EXPECT_NEAR(found.camera_matrix(0, 0), 379.1, 0.005 * 379.1);
  EXPECT_NEAR(found.camera_matrix(1, 1), 378.5, 0.005 * 378.5);
  // The lens terms trade against each other over the part of the image the
  // boards cover (k1 alone came out -0.229 with g++ and -0.179 with clang's
  // sanitizer build): what must hold is where the camera puts the boards'
  // points. 0.2 px with the billowing term; 30.7 px without it.
  double worst_px = 0;
  for (const auto& point : seen) worst_px = std::max(worst_px, (found.Project(point) - wide.Project(point)).norm());
  EXPECT_LT(worst_px, 1.0) << "k " << found.distortion[0] << " " << found.distortion[1] << " " << found.distortion[4];
}

// y = a x + b (1e-10 x^2): b's column is thirteen orders below a's. Ceres' Covariance
// (SPARSE_QR, rank judged on the unscaled Jacobian) takes it for zero; the
// scaled one finds the exact (J^T J)^-1 of the well-posed problem.
struct BadlyScaledLine {
  double x, y;
  template <typename T>
  bool operator()(const T* a, const T* b, T* r) const {
    r[0] = a[0] * T(x * 1e4) + b[0] * T(1e-10 * x * x) - T(y);
    return true;
  }
};

TEST(ScaledCovariance, APoorlyScaledButWellPosedProblemIsNotCalledSingular) {
  double a = 1, b = 1;
  ceres::Problem problem;
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  for (int i = 1; i <= 1000; ++i) {
    const double x = i / 100.0;
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<BadlyScaledLine, 1, 1, 1>(new BadlyScaledLine{x, x}),
                             nullptr, &a, &b);
    const Eigen::Vector2d row(x * 1e4, 1e-10 * x * x);
    normal += row * row.transpose();
  }
  ceres::Covariance ceres_covariance({});
  EXPECT_FALSE(ceres_covariance.Compute(std::vector<const double*>{&a, &b}, &problem))
      << "Ceres' own covariance no longer fails here: the test no longer shows why ScaledCovariance exists";
  const auto covariance = ScaledCovariance(problem);
  ASSERT_TRUE(covariance);
  const Eigen::Matrix2d exact = normal.inverse();
  EXPECT_NEAR(covariance->Variance(&a, 0), exact(0, 0), 1e-6 * exact(0, 0));
  EXPECT_NEAR(covariance->Variance(&b, 0), exact(1, 1), 1e-6 * exact(1, 1));
}

// c and d enter only as their sum: no scaling makes that well posed.
struct Sum {
  template <typename T>
  bool operator()(const T* c, const T* d, T* r) const {
    r[0] = c[0] + d[0] - T(1);
    return true;
  }
};

TEST(ScaledCovariance, ARankDeficientProblemIsStillRefused) {
  double c = 1, d = 1;
  ceres::Problem problem;
  for (int i = 0; i < 10; ++i)
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Sum, 1, 1, 1>(new Sum), nullptr, &c, &d);
  EXPECT_FALSE(ScaledCovariance(problem));
}

}  // namespace
}  // namespace speckle
