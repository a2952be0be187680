// Pairing each board point's raw value with its true depth (stages/pairing.h;
// the import's pairing by stamp is StampPairing in depth_units_test.cc). On a
// raw image whose values are a known tilted plane plus noise: each sample's
// raw value is that plane at the point's sub-pixel position, its gradient
// the plane's slope, its depth the board point's z through the rig; windows
// with a hole, off the image or across the board's edge give no sample.
#include <gtest/gtest.h>

#include <random>

#include "stages/pairing.h"

namespace speckle {
namespace {

// The raw image: r = kR0 + kSlopeU u + kSlopeV v, a steeply tilted board
// (1.4 raw steps a pixel), plus Gaussian noise.
constexpr double kR0 = 500, kSlopeU = 1.2, kSlopeV = -0.8, kRawSigma = 0.7;
double PlaneRaw(double u, double v) { return kR0 + kSlopeU * u + kSlopeV * v; }

cv::Mat DrawRaw(std::mt19937& rng) {
  std::normal_distribution<double> noise(0, kRawSigma);
  cv::Mat raw(480, 640, CV_16U);
  for (int v = 0; v < raw.rows; ++v)
    for (int u = 0; u < raw.cols; ++u)
      raw.at<std::uint16_t>(v, u) = static_cast<std::uint16_t>(std::lround(PlaneRaw(u, v) + noise(rng)));
  return raw;
}

// Board points at sub-pixel positions on a 12 x 10 grid over the image's
// middle, each with its place on the board.
BoardInDepth Points(std::mt19937& rng) {
  std::uniform_real_distribution<double> sub_pixel(-0.5, 0.5);
  BoardInDepth board;
  board.depth_from_board.translation() = Eigen::Vector3d(-0.1, -0.08, 1.0);
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 12; ++i)
      board.points.push_back({Eigen::Vector3d(0.02 * i, 0.02 * j, 0),
                              Eigen::Vector2d(150 + 30 * i + sub_pixel(rng), 100 + 30 * j + sub_pixel(rng))});
  return board;
}

CameraCalibration Rig() {
  CameraCalibration cameras;
  cameras.depth.camera_matrix = cv::Matx33d(580, 0, 319.5, 0, 580, 239.5, 0, 0, 1);
  cameras.depth_from_colour.linear() = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY()).toRotationMatrix();
  cameras.depth_from_colour.translation() = Eigen::Vector3d(0.025, 0, 0);
  return cameras;
}

Eigen::Isometry3d ColourPose() {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 0).normalized()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(-0.12, -0.07, 1.05);
  return pose;
}

std::vector<PairedSample> Pair(const cv::Mat& raw, const BoardInDepth& board, const CameraCalibration& cameras) {
  const auto result = RunPairing({}, {3, 1, 0.5, 0, {}, raw, board, cameras, ColourPose()});
  if (!Accepted(result)) return {};
  return std::get<std::vector<PairedSample>>(result);
}

TEST(BoardPairing, RawIsTheLocalPlaneAtThePointsSubPixelPosition) {
  // A least-squares plane through 25 values of noise sigma (0.7, and 0.29
  // of rounding) evaluated at the window's centre scatters by 0.15 raw; over
  // 3 images of 120 points (measured: RMS 0.15-0.17, worst 0.49) every
  // sample within 4 of those (0.6) and the RMS within 0.1-0.2. The value
  // at the nearest whole pixel instead is up to half a pixel of slope (0.7
  // raw) off, 0.42 RMS.
  std::mt19937 rng(61);
  const CameraCalibration cameras = Rig();
  for (int draw = 0; draw < 3; ++draw) {
    const BoardInDepth board = Points(rng);
    const auto samples = Pair(DrawRaw(rng), board, cameras);
    ASSERT_EQ(samples.size(), board.points.size());
    double squares = 0;
    for (const PairedSample& s : samples) {
      const BoardPoint& point = board.points[static_cast<std::size_t>(s.board_point)];
      EXPECT_EQ(s.u, point.pixel.x());
      EXPECT_EQ(s.v, point.pixel.y());
      const double error = s.raw - PlaneRaw(s.u, s.v);
      EXPECT_LT(std::abs(error), 0.6) << "at " << s.u << ", " << s.v;
      squares += error * error;
      // The slope: 25 values over +-2 px pin it to 0.76 / sqrt(50) = 0.11
      // (measured: worst 0.34 of 720); 0.45 is 4 of those.
      EXPECT_NEAR(s.gradient_u, kSlopeU, 0.45);
      EXPECT_NEAR(s.gradient_v, kSlopeV, 0.45);
      // The true depth is the board point's z through the colour pose and the rig.
      EXPECT_NEAR(s.depth_m, (cameras.depth_from_colour * ColourPose() * point.in_board).z(), 1e-12);
      EXPECT_EQ(s.frame, 3);
      EXPECT_EQ(s.pose, 1);
    }
    const double rms = std::sqrt(squares / static_cast<double>(samples.size()));
    EXPECT_GT(rms, 0.1);
    EXPECT_LT(rms, 0.2);
  }
}

TEST(BoardPairing, WindowsWithHolesOffTheImageOrAcrossAnEdgeGiveNoSample) {
  std::mt19937 rng(62);
  cv::Mat raw = DrawRaw(rng);
  BoardInDepth board = Points(rng);
  const Eigen::Vector2d with_hole = board.points[5].pixel, across_edge = board.points[40].pixel;
  raw.at<std::uint16_t>(static_cast<int>(std::lround(with_hole.y())) + 1,
                        static_cast<int>(std::lround(with_hole.x())) - 2) = 2047;  // no reading
  // The board's edge: 60 raw steps (the wall behind) on one side of the window.
  const int eu = static_cast<int>(std::lround(across_edge.x())), ev = static_cast<int>(std::lround(across_edge.y()));
  for (int v = ev - 2; v <= ev + 2; ++v)
    for (int u = eu + 1; u <= eu + 2; ++u) raw.at<std::uint16_t>(v, u) += 60;
  board.points.push_back({Eigen::Vector3d::Zero(), Eigen::Vector2d(1.2, 200)});  // window off the image
  const auto samples = Pair(raw, board, Rig());
  EXPECT_EQ(samples.size(), board.points.size() - 3);
  for (const PairedSample& s : samples) {
    EXPECT_NE(s.board_point, 5);
    EXPECT_NE(s.board_point, 40);
    EXPECT_NE(s.board_point, static_cast<int>(board.points.size()) - 1);
  }
}

TEST(BoardPairing, NoPointWithACleanValueIsARejection) {
  const cv::Mat holes(480, 640, CV_16U, cv::Scalar(2047));
  std::mt19937 rng(63);
  const BoardInDepth board = Points(rng);
  const CameraCalibration cameras = Rig();
  const auto result = RunPairing({}, {0, 0, 0, 0, {}, holes, board, cameras, ColourPose()});
  ASSERT_FALSE(Accepted(result));
  EXPECT_EQ(std::get<Rejection>(result).stage, "pairing");
}

// A far board (squares of 4.3 px in the depth image) whose dark squares read
// 4 raw high: a square centre's 5 x 5 window holds its neighbours' pixels as
// well, so the bias its raw value carries is the window's share of dark
// pixels, and the sample's albedo must say that share, not the square's own
// 0 or 1 (which leaves up to 2 raw unexplained at centres and corners).
TEST(BoardPairing, AlbedoIsTheBoardsShareInTheRawValuesWindow) {
  constexpr double kFlatRaw = 900, kDarkBias = 4;
  const CameraCalibration cameras = Rig();
  const BoardGeometry geometry;  // 11 x 8 squares of 22.3 mm
  Eigen::Isometry3d depth_from_board = Eigen::Isometry3d::Identity();
  depth_from_board.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  depth_from_board.translation() = Eigen::Vector3d(-0.1, -0.08, 3.0);
  const Eigen::Isometry3d colour_from_board = cameras.depth_from_colour.inverse() * depth_from_board;
  const Eigen::Vector3d normal = depth_from_board.linear().col(2);
  cv::Mat raw(480, 640, CV_16U);
  for (int v = 0; v < raw.rows; ++v) {
    for (int u = 0; u < raw.cols; ++u) {
      const Eigen::Vector3d ray(cameras.depth.Undistort(Eigen::Vector2d(u, v)).homogeneous());
      const Eigen::Vector3d hit = normal.dot(depth_from_board.translation()) / normal.dot(ray) * ray;
      const double albedo = BoardAlbedo(geometry, (depth_from_board.inverse() * hit).head<2>());
      raw.at<std::uint16_t>(v, u) = static_cast<std::uint16_t>(std::lround(kFlatRaw + kDarkBias * (1 - albedo)));
    }
  }
  BoardInDepth board;
  board.board = geometry;
  board.depth_from_board = depth_from_board;
  const double s = geometry.square_size_m;
  for (int j = 0; j < geometry.squares_y; ++j) {
    for (int i = 0; i < geometry.squares_x; ++i) {
      const Eigen::Vector3d centre((i + 0.5) * s, (j + 0.5) * s, 0), corner(i * s, j * s, 0);
      board.points.push_back({centre, cameras.depth.Project(depth_from_board * centre), SamplePoint::kSquareCentre});
      board.points.push_back({corner, cameras.depth.Project(depth_from_board * corner), SamplePoint::kInteriorCorner});
    }
  }
  const auto result = RunPairing({}, {0, 0, 0, 0, {}, raw, board, cameras, colour_from_board});
  ASSERT_TRUE(Accepted(result));
  const auto& samples = std::get<std::vector<PairedSample>>(result);
  ASSERT_GT(samples.size(), 100u);
  int mixed = 0;
  for (const PairedSample& sample : samples) {
    // Whole raw units: the plane fit averages 25 roundings to about 0.1 raw.
    EXPECT_NEAR(sample.raw, kFlatRaw + kDarkBias * (1 - sample.albedo), 0.4) << "at " << sample.u << ", " << sample.v;
    mixed += sample.albedo > 0.2 && sample.albedo < 0.8 && sample.point == SamplePoint::kSquareCentre;
  }
  EXPECT_GT(mixed, 20) << "square centres whose window mixes dark and light";
}

}  // namespace
}  // namespace speckle
