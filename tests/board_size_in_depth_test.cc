// The board's size by the depth's own triangulation (stages/board_size_in_depth.h),
// on views whose outline and raw value are written here from a known sensor:
// its baseline, raw offset and focal length.
#include "stages/board_size_in_depth.h"

#include <gtest/gtest.h>

#include <random>

#include "synthetic_views.h"

namespace speckle {
namespace {

struct Sensor {
  double fx = 580, baseline_m = 0.075, raw_offset = 1090;
  CameraIntrinsics camera = synthetic::Camera(580, 580, 320, 240);  // its fx is the sensor's
  double outline_fattening_px = 0;                                  // every side of the outline moved out by this
  double raw_noise = 0.5;
};

// The raw value over the board's pixels, as its median reads it: raw is
// affine in the image for a plane, so its median is near its mean over the
// image, where a board point weighs 1 / z^3 (the pixels it covers).
double MeanRawInTheImage(const Sensor& sensor, const BoardGeometry& board, const Eigen::Isometry3d& pose) {
  double sum = 0, weight = 0;
  for (double u = 0.025; u < 1; u += 0.05)
    for (double v = 0.025; v < 1; v += 0.05) {
      const double z = (pose * Eigen::Vector3d(u * board.Width(), v * board.Height(), 0)).z();
      sum += (sensor.raw_offset - 8 * sensor.fx * sensor.baseline_m / z) / std::pow(z, 3);
      weight += 1 / std::pow(z, 3);
    }
  return sum / weight;
}

const Eigen::Isometry3d kSame = Eigen::Isometry3d::Identity();  // the colour camera taken at the depth camera

// What the pipeline would hold for a board of `board` posed `poses` in front of
// `sensor`.
std::vector<ExtrinsicsView> Views(const Sensor& sensor, const BoardGeometry& board,
                                  const std::vector<Eigen::Isometry3d>& poses, std::mt19937& rng) {
  std::normal_distribution<double> noise(0, sensor.raw_noise);
  std::vector<ExtrinsicsView> views;
  for (const auto& pose : poses) {
    ExtrinsicsView view;
    view.colour_from_board = pose;
    const auto outline = OutlineCorners(board);
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d p = pose * outline[i];
      view.quad.corners_px[i] = sensor.camera.Project(p);
      mean += view.quad.corners_px[i] / 4;
    }
    for (auto& corner : view.quad.corners_px)
      corner += sensor.outline_fattening_px * std::sqrt(2.0) * (corner - mean).normalized();
    view.quad.board_raw_median = MeanRawInTheImage(sensor, board, pose) + noise(rng);
    views.push_back(view);
  }
  return views;
}

class BoardSizeInDepthTest : public ::testing::Test {
 protected:
  BoardGeometry board{9, 7, 0.04};
  std::mt19937 rng{7};
  std::vector<Eigen::Isometry3d> poses = synthetic::SpreadPoses(board, 20, rng);
};

TEST_F(BoardSizeInDepthTest, MeasuresTheBoardWithoutTheFocalLengthOrTheRawOffset) {
  for (const double fx : {580.0, 380.0}) {  // stock and wide-angle optics
    Sensor sensor;
    sensor.fx = fx;
    sensor.camera = synthetic::Camera(fx, fx, 320, 240);
    sensor.raw_offset = fx == 580 ? 1090 : 1070;
    const auto size = MeasureBoardSizeInDepth({}, board, Views(sensor, board, poses, rng), sensor.camera, kSame);
    ASSERT_TRUE(size) << fx;
    EXPECT_NEAR(size->Ratio(), 1.0, 0.02) << fx;
    EXPECT_LT(std::abs(size->Ratio() - 1) / (size->sigma_m / size->stated_m), 3) << fx;
    EXPECT_EQ(size->views, 20);
    EXPECT_FALSE(size->OutsideFamily()) << fx;
  }
}

TEST_F(BoardSizeInDepthTest, TheLensIsTakenOutOfTheOutlines) {
  Sensor sensor;
  sensor.fx = 380;  // a wide-angle add-on, whose barrel shrinks a board near the image's edge
  sensor.camera = synthetic::Camera(380, 380, 320, 240, {-0.25, 0.08, 0, 0, 0});
  const auto size = MeasureBoardSizeInDepth({}, board, Views(sensor, board, poses, rng), sensor.camera, kSame);
  ASSERT_TRUE(size);
  EXPECT_NEAR(size->Ratio(), 1.0, 0.02);
}

TEST_F(BoardSizeInDepthTest, AConstantlyFattenedOutlineMovesTheOffsetNotTheSize) {
  Sensor sensor;
  sensor.outline_fattening_px = 1.5;
  const auto size = MeasureBoardSizeInDepth({}, board, Views(sensor, board, poses, rng), sensor.camera, kSame);
  ASSERT_TRUE(size);
  EXPECT_NEAR(size->Ratio(), 1.0, 0.03);
}

TEST_F(BoardSizeInDepthTest, AWrongSquareSizeIsOutsideTheFamily) {
  const auto views = Views({}, board, poses, rng);
  for (const double typed : {0.03, 0.05}) {  // the board has 0.04 m squares
    BoardGeometry described = board;
    described.square_size_m = typed;
    const auto size = MeasureBoardSizeInDepth({}, described, views, Sensor().camera, kSame);
    ASSERT_TRUE(size) << typed;
    EXPECT_NEAR(size->Ratio(), 0.04 / typed, 0.03) << typed;
    EXPECT_TRUE(size->OutsideFamily()) << typed;
  }
}

TEST_F(BoardSizeInDepthTest, FramesAtHalfWidthAreMeasuredOnTheDisparityGrid) {
  auto views = Views({}, board, poses, rng);
  for (auto& view : views)
    for (auto& corner : view.quad.corners_px) corner /= 2;
  const CameraIntrinsics half = synthetic::Camera(290, 290, 160, 120, {}, {320, 240});
  const auto size = MeasureBoardSizeInDepth({}, board, views, half, kSame);
  ASSERT_TRUE(size);
  EXPECT_NEAR(size->Ratio(), 1.0, 0.02);
}

TEST_F(BoardSizeInDepthTest, NothingIsMeasuredFromTooFewPosesOrOneDistance) {
  const auto views = Views({}, board, poses, rng);
  EXPECT_FALSE(MeasureBoardSizeInDepth({}, board, {views.begin(), views.begin() + 5}, Sensor().camera, kSame));
  std::vector<Eigen::Isometry3d> one_distance;
  for (int i = 0; i < 10; ++i)
    one_distance.push_back(synthetic::BoardPose(board, {0.01 * i, 0, 1.2}, 5.0 * i - 20, 0, 0));
  EXPECT_FALSE(MeasureBoardSizeInDepth({}, board, Views({}, board, one_distance, rng), Sensor().camera, kSame));
  // Many frames of two still poses are two views of the line, not twenty.
  std::vector<Eigen::Isometry3d> frames(10, poses[0]);
  frames.insert(frames.end(), 10, poses[1]);
  EXPECT_FALSE(MeasureBoardSizeInDepth({}, board, Views({}, board, frames, rng), Sensor().camera, kSame));
}

}  // namespace
}  // namespace speckle
