// Corrected clouds of simulated scenes whose truth is known: a flat wall
// comes out flat and at its distance, a board's edge leaves no flying pixels
// (where resampling leaves many), and the measuring tool's distances match
// the truth. Two calibrations of the simulated sensor: the true one, which
// isolates what applying does, and the one the pipeline fits on the golden
// session.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <random>

#include "apply/depth_corrector.h"
#include "apply/point_measure.h"
#include "model/depth_model.h"
#include "model/undistortion_grid.h"
#include "simulator/session_simulator.h"
#include "test_util.h"

namespace speckle::testing {
namespace {

using apply::DepthCorrector;
using apply::OrganizedCloud;

class AppliedScene : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scratch_ = new ScratchDir;
    calibration_ = new apply::DepthCalibration(apply::LoadDepthCalibration(CalibratedGoldenSession(scratch_->path())));
    simulator_ = new sim::SessionSimulator(
        sim::ScenarioFromJson(ReadJson(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "scenario.json"), "golden"));
    truth_ = new apply::DepthCalibration(TrueCalibration());
  }
  static void TearDownTestSuite() {
    delete truth_;
    delete simulator_;
    delete calibration_;
    delete scratch_;
  }

  // The simulated sensor's own cameras and reciprocal base form (the golden
  // scenario has no depth effects), as a calibration.
  static apply::DepthCalibration TrueCalibration() {
    const sim::SensorOptics& optics = simulator_->optics();
    const auto camera = [](const sim::CameraModel& m) {
      return apply::PinholeCamera{m.size.width, m.size.height, m.fx, m.fy, m.cx, m.cy, m.distortion};
    };
    apply::DepthCalibration c = *calibration_;
    c.depth = camera(optics.ir), c.colour = camera(optics.colour);
    c.depth_from_colour = optics.colour_from_ir.inverse();
    model::ModelDefinition definition;
    definition.form = model::BaseForm::kReciprocal;
    auto m = std::make_shared<model::DepthModel>(definition);
    const sim::DepthFormation& formation = simulator_->scenario().depth;
    m->Base() = {formation.a, formation.b};
    c.model = m;
    c.grid.reset();
    return c;
  }

  // A target straight ahead: a wall filling the view, or the board (its
  // corner at the given offset) in front of the rig's background wall.
  static sim::SimFrameSpec Facing(double z_m, bool board, double x_m = 0, double y_m = 0) {
    sim::SimFrameSpec spec;
    spec.context.recording = board ? sim::SimRecording::kDepthboard : sim::SimRecording::kPlanar;
    spec.context.seed = simulator_->scenario().seed;
    spec.depth_target.ir_from_target.translation() = Eigen::Vector3d(x_m, y_m, z_m);
    spec.depth_target.is_board = board;
    spec.colour_target = spec.depth_target;
    return spec;
  }
  static cv::Mat Raw(const sim::SimFrameSpec& spec, std::uint64_t noise_seed) {
    std::mt19937_64 rng(noise_seed);
    return simulator_->renderer().RawFromDepth(simulator_->TrueDepth(spec), spec.context, rng);
  }
  static OrganizedCloud Correct(const cv::Mat& raw, const apply::DepthCalibration& calibration) {
    const DepthCorrector corrector(calibration);
    return corrector.Cloud({raw.ptr<std::uint16_t>(), raw.total()}, 0);
  }
  // The true point behind each depth pixel (NaN where the ray hits nothing).
  static std::vector<Eigen::Vector3d> TruePoints(const sim::SimFrameSpec& spec) {
    const cv::Mat z = simulator_->TrueDepth(spec).z_m;
    std::vector<Eigen::Vector3d> points(z.total(), Eigen::Vector3d::Constant(NAN));
    for (int v = 0; v < z.rows; ++v)
      for (int u = 0; u < z.cols; ++u)
        if (z.at<double>(v, u) > 0)
          points[v * z.cols + u] = z.at<double>(v, u) * simulator_->renderer().DepthRay(u, v).homogeneous();
    return points;
  }

  static ScratchDir* scratch_;
  static apply::DepthCalibration *calibration_, *truth_;
  static sim::SessionSimulator* simulator_;
};
ScratchDir* AppliedScene::scratch_ = nullptr;
apply::DepthCalibration* AppliedScene::calibration_ = nullptr;
apply::DepthCalibration* AppliedScene::truth_ = nullptr;
sim::SessionSimulator* AppliedScene::simulator_ = nullptr;

// RMS distance of points to their least-squares plane.
double PlaneRms(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) scatter += (p - mean) * (p - mean).transpose();
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvalues()[0] /
                   static_cast<double>(points.size()));
}

struct WallFit {
  double noise_m = 0;       // one point's scatter along z, from two exposures
  double plane_rms_m = 0;   // distance of the points to their best plane
  double mean_error_m = 0;  // mean corrected depth less the true one
};

TEST_F(AppliedScene, FlatWallIsFlatWithinNoiseAndAtItsDistance) {
  const auto fit = [](const sim::SimFrameSpec& wall, const apply::DepthCalibration& calibration) {
    const OrganizedCloud a = Correct(Raw(wall, 1), calibration), b = Correct(Raw(wall, 2), calibration);
    const std::vector<Eigen::Vector3d> truth = TruePoints(wall);
    double noise_sum = 0, error_sum = 0;
    std::vector<Eigen::Vector3d> points;
    for (std::size_t p = 0; p < truth.size(); ++p) {
      if (std::isnan(a.xyz[3 * p + 2]) || std::isnan(b.xyz[3 * p + 2])) continue;
      const double d = a.xyz[3 * p + 2] - b.xyz[3 * p + 2];
      noise_sum += d * d / 2;
      error_sum += a.xyz[3 * p + 2] - truth[p].z();
      points.emplace_back(a.xyz[3 * p], a.xyz[3 * p + 1], a.xyz[3 * p + 2]);
    }
    EXPECT_GT(points.size(), 250000u);
    const double n = static_cast<double>(points.size());
    return WallFit{std::sqrt(noise_sum / n), PlaneRms(points), error_sum / n};
  };
  for (const double distance : {1.0, 2.0}) {
    const sim::SimFrameSpec wall = Facing(distance, false);
    const WallFit truth = fit(wall, *truth_), fitted = fit(wall, *calibration_);
    std::cout << distance << " m wall, true calibration: noise " << 1e3 * truth.noise_m << " mm, plane rms "
              << 1e3 * truth.plane_rms_m << " mm, mean error " << 1e3 * truth.mean_error_m << " mm\n"
              << distance << " m wall, golden session's fit: noise " << 1e3 * fitted.noise_m << " mm, plane rms "
              << 1e3 * fitted.plane_rms_m << " mm, mean error " << 1e3 * fitted.mean_error_m << " mm\n";
    EXPECT_LT(truth.plane_rms_m, 1.1 * truth.noise_m) << "flat within noise";
    EXPECT_LT(std::abs(truth.mean_error_m), 0.1 * truth.noise_m) << "at its distance within noise";
    // The fitted grid and lens keep the wall as flat; the fit's own scale
    // error (its colour camera's focal length, from 8 views) moves it.
    EXPECT_LT(fitted.plane_rms_m, 1.1 * fitted.noise_m) << "the fitted calibration: flat within noise";
  }
}

// The usual way, for comparison: raw to depth per pixel, resampled onto the
// undistorted image with bilinear cv::remap, unprojected through the pinhole;
// the points of the pixels inside `region`.
std::vector<Eigen::Vector3d> ResampledCloud(const cv::Mat& raw, const apply::DepthCalibration& c,
                                            const cv::Rect& region) {
  cv::Mat depth(raw.size(), CV_32F);
  for (int v = 0; v < raw.rows; ++v)
    for (int u = 0; u < raw.cols; ++u) {
      const int r = raw.at<std::uint16_t>(v, u);
      depth.at<float>(v, u) = r >= 2047 ? 0.0f : static_cast<float>(c.model->Depth({.raw = static_cast<double>(r)}));
    }
  const cv::Matx33d k(c.depth.fx, 0, c.depth.cx, 0, c.depth.fy, c.depth.cy, 0, 0, 1);
  cv::Mat map_x, map_y, rectified;
  cv::initUndistortRectifyMap(k, cv::Mat(c.depth.distortion), cv::Mat(), k, raw.size(), CV_32FC1, map_x, map_y);
  cv::remap(depth, rectified, map_x, map_y, cv::INTER_LINEAR);
  std::vector<Eigen::Vector3d> points;
  for (int v = 0; v < raw.rows; ++v)
    for (int u = 0; u < raw.cols; ++u) {
      const double z = rectified.at<float>(v, u);
      if (z > 0 && region.contains({u, v}))
        points.emplace_back(z * (u - c.depth.cx) / c.depth.fx, z * (v - c.depth.cy) / c.depth.fy, z);
    }
  return points;
}

TEST_F(AppliedScene, BoardEdgeLeavesNoFlyingPixels) {
  // The board 1 m away, towards the top left where the lens bends most, in
  // front of the rig's wall 3.2 m away: around the board every point belongs
  // near one or the other, none in the 2 m gap between them.
  const sim::RigSpec& rig = simulator_->scenario().rig;
  const double board_z = 1.0, wall_z = rig.background_depth_m;
  const sim::SimFrameSpec scene = Facing(board_z, true, -0.45, -0.3);
  const cv::Mat raw = Raw(scene, 1);
  const auto in_gap = [&](double z) { return z > board_z + 0.15 && z < wall_z - 0.3; };
  // The board's pixels, and 20 more on every side: board and wall only (the
  // floor and ceiling, which do lie between, are far outside).
  const cv::Mat true_z = simulator_->TrueDepth(scene).z_m;
  cv::Mat on_board;
  cv::inRange(true_z, board_z - 0.01, board_z + 0.01, on_board);
  const cv::Rect board_box = cv::boundingRect(on_board);
  const cv::Rect region = cv::Rect(board_box.x - 20, board_box.y - 20, board_box.width + 40, board_box.height + 40) &
                          cv::Rect(0, 0, raw.cols, raw.rows);
  const OrganizedCloud cloud = Correct(raw, *truth_);
  int corrected_gap = 0, board_points = 0;
  for (int v = region.y; v < region.br().y; ++v)
    for (int u = region.x; u < region.br().x; ++u) {
      const float z = cloud.xyz[3 * (v * raw.cols + u) + 2];
      corrected_gap += in_gap(z);
      board_points += std::abs(z - board_z) < 0.05;
    }
  int resampled_gap = 0;
  for (const Eigen::Vector3d& p : ResampledCloud(raw, *truth_, region)) resampled_gap += in_gap(p.z());
  std::cout << "points between board and wall: " << corrected_gap << " corrected, " << resampled_gap
            << " resampled (bilinear remap); " << board_points << " on the board\n";
  EXPECT_GT(board_points, 10000);
  EXPECT_GT(resampled_gap, 150) << "resampling blends board and wall along the outline";
  EXPECT_LE(corrected_gap, 2);
}

TEST_F(AppliedScene, MeasuredDistancesMatchTheTruth) {
  const sim::RigSpec& rig = simulator_->scenario().rig;
  const sim::SimFrameSpec scene =
      Facing(1.2, true, -0.5 * rig.squares_x * rig.square_size_m, -0.5 * rig.squares_y * rig.square_size_m);
  const OrganizedCloud cloud = Correct(Raw(scene, 3), *truth_);
  const std::vector<Eigen::Vector3d> truth = TruePoints(scene);
  // Across the board, and from the board to the wall behind it.
  for (const auto& [from, to] :
       {std::pair{cv::Point(290, 225), cv::Point(345, 262)}, std::pair{cv::Point(300, 240), cv::Point(60, 60)}}) {
    ASSERT_NEAR(truth[from.y * 640 + from.x].z(), 1.2, 1e-9) << "on the board";
    const apply::Measurement m = apply::Measure(cloud, from.x, from.y, to.x, to.y, 2);
    const double true_distance = (truth[to.y * 640 + to.x] - truth[from.y * 640 + from.x]).norm();
    std::cout << "measured " << 1e3 * m.distance_m << " mm, true " << 1e3 * true_distance << " mm\n";
    EXPECT_NEAR(m.distance_m, true_distance, 0.003 + 0.003 * true_distance);
  }
  EXPECT_THROW(apply::Measure(cloud, 0, 0, 700, 10, 0), InputError);
  const OrganizedCloud empty{640, 480, std::vector<float>(3 * 640 * 480, NAN), {}};
  try {
    apply::Measure(empty, 10, 10, 20, 20, 3);
    ADD_FAILURE() << "a pixel without a point was measured";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pixel (10, 10): no depth reading within 3 pixels"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace speckle::testing
