// The depth pose on outlines projected through a known depth camera (with the
// IR lens's strong k2): from an exact outline it is the pose itself, and each
// board point lands where that pose projects it, named by kind and by the
// shade of its square; from a noisy outline the board's depth is unbiased.
#include <gtest/gtest.h>

#include <random>

#include "stages/depth_pose.h"
#include "stages/outline_calibration.h"
#include "synthetic_views.h"

namespace speckle {
namespace {

const BoardGeometry kBoard{11, 8, 0.0223};
// A stock Kinect IR camera as the thesis's App. A measured it (k2 ~ 0.48).
const CameraIntrinsics kDepth = synthetic::Camera(588.9, 586.2, 316.8, 252.1, {-0.11, 0.48, 0.0012, -0.0009, 0});

DepthboardQuad Outline(const Eigen::Isometry3d& depth_from_board) {
  DepthboardQuad quad;
  const auto corners = OutlineCorners(kBoard);
  for (int k = 0; k < 4; ++k) quad.corners_px[k] = kDepth.Project(depth_from_board * corners[k]);
  return quad;
}

TEST(DepthPose, ExactOutlineGivesThePoseAndWhereItsPointsAre) {
  std::mt19937 rng(21);
  for (const auto& truth : synthetic::SpreadPoses(kBoard, 8, rng)) {
    const auto result = RunDepthPose({}, kBoard, kDepth, Outline(truth));
    ASSERT_TRUE(Accepted(result)) << std::get<Rejection>(result).reason;
    const BoardInDepth& found = std::get<BoardInDepth>(result);
    // Four exact corners fix a plane's pose exactly: what is left is the
    // solver's convergence, micrometres (a 0.1 px error would be 0.2 mm).
    EXPECT_LT((found.depth_from_board.translation() - truth.translation()).norm(), 1e-5);
    EXPECT_LT(Eigen::AngleAxisd(found.depth_from_board.linear() * truth.linear().transpose()).angle(), 1e-5);
    ASSERT_EQ(found.points.size(), 70u + 88u);  // interior corners, then square centres
    for (const BoardPoint& p : found.points) {
      EXPECT_NEAR(p.in_board.z(), 0, 1e-12);
      EXPECT_LT((p.pixel - kDepth.Project(truth * p.in_board)).norm(), 1e-3) << p.in_board.transpose();
    }
    // The first interior corner is the one next to square (0, 0), as the
    // chessboard detection orders them, and rows run along x.
    EXPECT_LT((found.points[0].in_board - Eigen::Vector3d(0.0223, 0.0223, 0)).norm(), 1e-12);
    EXPECT_LT((found.points[1].in_board - Eigen::Vector3d(2 * 0.0223, 0.0223, 0)).norm(), 1e-12);
  }
}

TEST(DepthPose, PointsAreNamedByKindAndTheBoardsShadesByItsSquares) {
  const auto result = RunDepthPose({}, kBoard, kDepth, Outline(synthetic::BoardPose(kBoard, {0, 0, 1}, 5, 5, 0)));
  ASSERT_TRUE(Accepted(result));
  const auto& points = std::get<BoardInDepth>(result).points;
  const double s = kBoard.square_size_m;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const BoardPoint& p = points[k];
    if (k < 70) {
      EXPECT_EQ(p.kind, SamplePoint::kInteriorCorner);
      continue;
    }
    EXPECT_EQ(p.kind, SamplePoint::kSquareCentre);
    const int i = static_cast<int>(std::floor(p.in_board.x() / s)),
              j = static_cast<int>(std::floor(p.in_board.y() / s));
    EXPECT_NEAR(p.in_board.x(), (i + 0.5) * s, 1e-12);
    EXPECT_NEAR(p.in_board.y(), (j + 0.5) * s, 1e-12);
    // Square (0, 0) is dark (the chessboard detection's canonical order),
    // and the shades alternate; off the chessboard the shade is unknown.
    EXPECT_EQ(BoardAlbedo(kBoard, p.in_board.head<2>()), (i + j) % 2 == 0 ? 0.0 : 1.0) << "square " << i << ", " << j;
  }
  const auto corners_only =
      RunDepthPose({false}, kBoard, kDepth, Outline(synthetic::BoardPose(kBoard, {0, 0, 1}, 5, 5, 0)));
  ASSERT_TRUE(Accepted(corners_only));
  EXPECT_EQ(std::get<BoardInDepth>(corners_only).points.size(), 70u);
  EXPECT_EQ(BoardAlbedo(kBoard, Eigen::Vector2d(-0.001, 0.01)), 0.5);
  EXPECT_EQ(BoardAlbedo(kBoard, Eigen::Vector2d(0.01, kBoard.Height() + 0.001)), 0.5);
}

TEST(DepthPose, NoisyOutlineGivesAnUnbiasedBoardDepth) {
  // The quads' corners scatter by 0.3 px (their line fits). Over 300 draws
  // the board centre's depth error averages to zero within 3 standard errors
  // (measured: sd 4.5 mm, so 0.8 mm; mean -0.13 mm): the IR lens dropped
  // moves it by about a centimetre.
  std::mt19937 rng(22);
  std::normal_distribution<double> noise(0, 0.3);
  const Eigen::Isometry3d truth = synthetic::BoardPose(kBoard, {0.12, -0.08, 1.3}, 25, -20, 10);
  const Eigen::Vector3d centre(kBoard.Width() / 2, kBoard.Height() / 2, 0);
  constexpr int kDraws = 300;
  double sum = 0, squares = 0;
  for (int draw = 0; draw < kDraws; ++draw) {
    DepthboardQuad quad = Outline(truth);
    for (auto& c : quad.corners_px) c += Eigen::Vector2d(noise(rng), noise(rng));
    const auto result = RunDepthPose({}, kBoard, kDepth, quad);
    ASSERT_TRUE(Accepted(result));
    const double dz = (std::get<BoardInDepth>(result).depth_from_board * centre).z() - (truth * centre).z();
    sum += dz, squares += dz * dz;
  }
  const double mean = sum / kDraws, sd = std::sqrt(squares / kDraws - mean * mean);
  EXPECT_LT(std::abs(mean), 3 * sd / std::sqrt(kDraws)) << "mean " << mean << " m, sd " << sd << " m";
  EXPECT_LT(sd, 0.01) << "four corners at 0.3 px pin the depth to millimetres";
}

}  // namespace
}  // namespace speckle
