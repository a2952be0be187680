// Still-board averaging before quad extraction: on synthetic depthboard frames
// whose outline flickers like a Kinect's, the outline found in the median of a
// still pose's frames is closer to the true corners than the outline found in
// each frame alone. A Kinect matches speckle blocks several pixels wide, so
// its edge errors come in runs along the edge, which a line fit through one
// frame cannot average away: the outline wanders in and out by a noise
// (σ 0.7 px) that is smooth over about 6 px along it and new in every frame.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "stages/depthboard_quad.h"
#include "stages/still_frame_average.h"

namespace speckle {
namespace {

constexpr std::uint16_t kBoardRaw = 800, kWallRaw = 1000, kNoReading = 2047;

// Signed distance of pixel centre (u, v) from the quadrilateral's outline,
// positive inside.
double InsideBy(const std::array<Eigen::Vector2d, 4>& quad, int u, int v) {
  double inside = 1e9;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d a = quad[k], e = (quad[(k + 1) % 4] - a).normalized(), d = Eigen::Vector2d(u, v) - a;
    inside = std::min(inside, e.x() * d.y() - e.y() * d.x());
  }
  return inside;
}

cv::Mat FlickeringFrame(const std::array<Eigen::Vector2d, 4>& quad, std::mt19937& rng) {
  std::normal_distribution<double> block_flicker(0, 0.7), noise(0, 1.0);
  std::bernoulli_distribution dropout(0.02);
  cv::Mat coarse(480 / 6 + 1, 640 / 6 + 1, CV_64FC1), flicker;
  for (auto it = coarse.begin<double>(); it != coarse.end<double>(); ++it) *it = block_flicker(rng);
  cv::resize(coarse, flicker, cv::Size(640, 480), 0, 0, cv::INTER_LINEAR);
  cv::Mat raw(480, 640, CV_16UC1);
  for (int v = 0; v < raw.rows; ++v) {
    for (int u = 0; u < raw.cols; ++u) {
      const bool board = InsideBy(quad, u, v) + flicker.at<double>(v, u) > 0;
      raw.at<std::uint16_t>(v, u) =
          dropout(rng) ? kNoReading
                       : static_cast<std::uint16_t>(std::lround((board ? kBoardRaw : kWallRaw) + noise(rng)));
    }
  }
  return raw;
}

double MeanCornerError(const StageResult<DepthboardQuad>& found, const std::array<Eigen::Vector2d, 4>& truth) {
  EXPECT_TRUE(Accepted(found)) << (Accepted(found) ? "" : std::get<Rejection>(found).reason);
  if (!Accepted(found)) return 1e9;
  double sum = 0;
  for (int k = 0; k < 4; ++k) sum += (std::get<DepthboardQuad>(found).corners_px[k] - truth[k]).norm() / 4;
  return sum;
}

TEST(StillFrameAverage, OutlineOfAStillBoardIsCloserToTheTruthThanAnySingleFrames) {
  // Counter-clockwise in image coordinates (y down) so "inside" is on the left.
  const std::array<Eigen::Vector2d, 4> truth = {Eigen::Vector2d(221.3, 142.7), Eigen::Vector2d(402.6, 151.2),
                                                Eigen::Vector2d(395.1, 301.9), Eigen::Vector2d(214.8, 290.4)};
  std::array<Eigen::Vector2d, 4> predicted = truth;
  for (auto& p : predicted) p += Eigen::Vector2d(3, -2);  // the colour pose is a few pixels off
  std::mt19937 rng(7);
  double single = 0, averaged = 0;
  constexpr int kPoses = 4, kFrames = 7;
  for (int pose = 0; pose < kPoses; ++pose) {
    std::vector<cv::Mat> frames;
    for (int f = 0; f < kFrames; ++f) frames.push_back(FlickeringFrame(truth, rng));
    for (const cv::Mat& f : frames)
      single += MeanCornerError(RunDepthboardQuadExtraction({}, {f, predicted}), truth) / (kPoses * kFrames);
    const auto median = RunStillFrameAverage({}, frames, DepthReading{});
    ASSERT_TRUE(Accepted(median));
    averaged +=
        MeanCornerError(RunDepthboardQuadExtraction({}, {std::get<cv::Mat>(median), predicted}), truth) / kPoses;
  }
  RecordProperty("single_frame_corner_error_px", std::to_string(single));
  RecordProperty("averaged_corner_error_px", std::to_string(averaged));
  std::printf("mean corner error: single frames %.3f px, median of %d frames %.3f px\n", single, kFrames, averaged);
  EXPECT_LT(averaged, 0.7 * single);
}

TEST(StillFrameAverage, MedianOfValidReadingsAndMajorityValidity) {
  const auto frame = [](std::uint16_t a, std::uint16_t b) {
    cv::Mat m(1, 2, CV_16UC1);
    m.at<std::uint16_t>(0, 0) = a;
    m.at<std::uint16_t>(0, 1) = b;
    return m;
  };
  // Pixel 0: board, board, background, no reading -> board (the median of valid ones).
  // Pixel 1: valid in only one of four frames -> no reading.
  const auto result = RunStillFrameAverage(
      {}, {frame(800, kNoReading), frame(801, kNoReading), frame(1000, 900), frame(kNoReading, kNoReading)},
      DepthReading{});
  ASSERT_TRUE(Accepted(result));
  const cv::Mat& m = std::get<cv::Mat>(result);
  EXPECT_EQ(m.at<std::uint16_t>(0, 0), 801);
  EXPECT_EQ(m.at<std::uint16_t>(0, 1), kNoReading);
}

TEST(StillFrameAverage, FramesThatDoNotMatchAreRejectedWithTheReason) {
  const auto empty = RunStillFrameAverage({}, {}, DepthReading{});
  ASSERT_FALSE(Accepted(empty));
  EXPECT_NE(std::get<Rejection>(empty).reason.find("no frames"), std::string::npos);
  const auto mixed = RunStillFrameAverage(
      {}, {cv::Mat(480, 640, CV_16UC1, cv::Scalar(800)), cv::Mat(240, 320, CV_16UC1, cv::Scalar(800))}, DepthReading{});
  ASSERT_FALSE(Accepted(mixed));
  EXPECT_NE(std::get<Rejection>(mixed).reason.find("frame 1"), std::string::npos) << std::get<Rejection>(mixed).reason;
  const auto wrong_type = RunStillFrameAverage({}, {cv::Mat(480, 640, CV_32FC1, cv::Scalar(800))}, DepthReading{});
  EXPECT_FALSE(Accepted(wrong_type));
}

}  // namespace
}  // namespace speckle
