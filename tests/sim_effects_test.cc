// Each simulator effect changes the data the way its physics says, the base
// forms hold, ideal pairs fit the true reciprocal model back, and OpenCV finds
// the simulated chessboard.
#include <gtest/gtest.h>

#include <ceres/ceres.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "model/depth_model.h"
#include "schemas/errors.h"
#include "simulator/session_simulator.h"

namespace speckle::sim {
namespace {

using nlohmann::json;

// Walls at the given distances, one frame each, no noise or clutter.
json Walls(double near_m, double far_m, int snapshots, json effects = json::object()) {
  return {{"depthboard", {{"poses", 0}}},
          {"ir_chessboard", {{"poses", 0}}},
          {"planar",
           {{"snapshots", snapshots},
            {"frames_per_snapshot", 1},
            {"min_depth_m", near_m},
            {"max_depth_m", far_m},
            {"clutter_probability", 0}}},
          {"depth_model", {{"raw_noise_sigma", 0}}},
          {"room", {{"floor_below_m", 9}, {"ceiling_above_m", 9}}},
          {"effects", effects}};
}

json Boards(int poses, json effects = json::object(), double noise = 0) {
  return {{"depthboard", {{"poses", poses}, {"frames_per_pose", 1}}},
          {"planar", {{"snapshots", 0}}},
          {"ir_chessboard", {{"poses", 0}}},
          {"depth_model", {{"raw_noise_sigma", noise}}},
          {"effects", effects}};
}

cv::Mat Render(const SessionSimulator& sim, SimRecording which, int index) {
  return sim.Render(which, sim.Frames(which).at(static_cast<std::size_t>(index))).raw_depth;
}

double Raw(const cv::Mat& raw, int u, int v) { return raw.at<std::uint16_t>(v, u); }

// Raw value minus the ideal raw value of the true depth, per pixel (NaN where invalid).
cv::Mat Excess(const SessionSimulator& sim, SimRecording which, int index) {
  const auto& spec = sim.Frames(which).at(static_cast<std::size_t>(index));
  const cv::Mat raw = sim.Render(which, spec).raw_depth;
  const DepthTruth truth = sim.TrueDepth(spec);
  cv::Mat excess(raw.size(), CV_64F, cv::Scalar(std::nan("")));
  for (int v = 0; v < raw.rows; ++v)
    for (int u = 0; u < raw.cols; ++u)
      if (raw.at<std::uint16_t>(v, u) != 2047)
        excess.at<double>(v, u) =
            raw.at<std::uint16_t>(v, u) - sim.scenario().depth.RawFromDepth(truth.z_m.at<double>(v, u));
  return excess;
}

TEST(RadialBillow, FlatWallBecomesConvexMoreHorizontallyAndLessAtDistance) {
  const SessionSimulator sim(
      ScenarioFromJson(Walls(0.8, 2.4, 2, {{"radial_billow", {{"bx_raw2", 60000}, {"by_raw2", 20000}}}}), "test"));
  for (int i = 0; i < 2; ++i) {
    const cv::Mat raw = Render(sim, SimRecording::kPlanar, i);
    EXPECT_GT(Raw(raw, 40, 252), Raw(raw, 315, 252) + 5) << "the wall's sides should read farther than its centre";
  }
  const cv::Mat near = Render(sim, SimRecording::kPlanar, 0), far = Render(sim, SimRecording::kPlanar, 1);
  // Same normalized radius (0.46) horizontally and vertically: x at u = 45, y at v = 524 is off the image,
  // so compare equal pixel offsets scaled by the focal lengths (nearly equal).
  const double horizontal = Raw(near, 315 - 220, 252) - Raw(near, 315, 252);
  const double vertical = Raw(near, 315, 252 - 220) - Raw(near, 315, 252);
  EXPECT_GT(horizontal, 1.5 * vertical);
  const double near_bulge = Raw(near, 40, 252) - Raw(near, 315, 252);
  const double far_bulge = Raw(far, 40, 252) - Raw(far, 315, 252);
  EXPECT_LT(far_bulge, 0.8 * near_bulge) << "billowing in raw units weakens with distance";
}

TEST(ThermalDrift, OffsetGrowsWithTimeAsTheModelSays) {
  const SessionSimulator sim(ScenarioFromJson(
      Walls(1.0, 1.0, 8, {{"thermal_drift", {{"amplitude_raw", 8}, {"time_constant_s", 60}}}}), "test"));
  // What the depth model's own catalogue effect (model/effects/thermal_drift.h)
  // says with the same amplitude and time constant: the drift the simulator
  // hides is one the model can represent, not a restatement of its formula.
  const auto drift = model::CreateEffect(model::EffectSpecFromJson("thermal_drift", "test"));
  const double parameters[] = {8, 60};
  double previous = -1;
  for (int i = 0; i < 8; ++i) {
    const double t = sim.Frames(SimRecording::kPlanar)[static_cast<std::size_t>(i)].context.time_s;
    const double excess = cv::mean(Excess(sim, SimRecording::kPlanar, i)(cv::Rect(300, 220, 40, 40)))[0];
    model::Covariates at;
    at.time_s = t;
    EXPECT_NEAR(excess, drift->RawOffset(parameters, at), 0.6) << "at t = " << t;
    EXPECT_GE(excess, previous - 0.5);
    previous = excess;
  }
  EXPECT_GT(previous, 7) << "by the last snapshot the drift has nearly saturated";
}

TEST(ImageLinearOffset, RawOffsetRampsAcrossTheImage) {
  const SessionSimulator sim(ScenarioFromJson(
      Walls(1.0, 1.0, 1, {{"image_linear_offset", {{"slope_x_raw", 8}, {"slope_y_raw", -5}}}}), "test"));
  const cv::Mat excess = Excess(sim, SimRecording::kPlanar, 0);
  const auto at = [&](int u, int v) { return cv::mean(excess(cv::Rect(u - 10, v - 10, 20, 20)))[0]; };
  // About 580 px per unit of x and y: 440 px across is 0.76 x, 300 px down is 0.52 y.
  EXPECT_NEAR(at(540, 240) - at(100, 240), 8 * 440 / 580.0, 0.8);
  EXPECT_NEAR(at(320, 390) - at(320, 90), -5 * 300 / 580.0, 0.8);
  EXPECT_NEAR(at(320, 240), 0, 0.6) << "no offset at the image centre";
}

TEST(DepthGridOffset, DepthEdgesMoveByTheOffset) {
  const json effect = {{"depth_grid_offset", {{"dx_px", 4}, {"dy_px", -3}}}};
  const SessionSimulator plain(ScenarioFromJson(Boards(2), "test"));
  const SessionSimulator shifted(ScenarioFromJson(Boards(2, effect), "test"));
  const cv::Mat a = Render(plain, SimRecording::kDepthboard, 0), b = Render(shifted, SimRecording::kDepthboard, 0);
  // Depth pixel (u, v) of the shifted sensor sees what (u + 4, v - 3) of the plain one sees.
  int compared = 0, equal = 0, edge_pixels = 0;
  for (int v = 20; v < 460; ++v) {
    for (int u = 20; u < 620; ++u) {
      const bool edge = std::abs(Raw(a, u, v) - Raw(a, u + 1, v)) > 20;
      edge_pixels += edge;
      if (!edge) continue;
      ++compared;
      equal += Raw(b, u - 4, v + 3) == Raw(a, u, v);
    }
  }
  ASSERT_GT(edge_pixels, 50) << "the board should make depth edges";
  EXPECT_GT(double(equal) / compared, 0.95);
}

TEST(AlbedoBias, FollowsTheDarkSquares) {
  const SessionSimulator sim(ScenarioFromJson(Boards(3, {{"albedo_bias", {{"dark_bias_raw", 10}}}}), "test"));
  for (int i = 0; i < 3; ++i) {
    const auto& spec = sim.Frames(SimRecording::kDepthboard)[static_cast<std::size_t>(i)];
    const cv::Mat excess = Excess(sim, SimRecording::kDepthboard, i);
    const cv::Mat albedo = sim.TrueDepth(spec).albedo;
    double dark = 0, light = 0;
    int n_dark = 0, n_light = 0;
    for (int v = 0; v < excess.rows; ++v) {
      for (int u = 0; u < excess.cols; ++u) {
        const double e = excess.at<double>(v, u);
        if (std::isnan(e)) continue;
        if (albedo.at<float>(v, u) < 0.2f) dark += e, ++n_dark;
        if (albedo.at<float>(v, u) > 0.8f) light += e, ++n_light;
      }
    }
    ASSERT_GT(n_dark, 100);
    EXPECT_NEAR(dark / n_dark, 9.0, 0.5);    // 10 * (1 - 0.1)
    EXPECT_NEAR(light / n_light, 1.0, 0.5);  // 10 * (1 - 0.9)
  }
}

TEST(DisparityPattern, SamePatternEverywhereDecayingWithDisparity) {
  const SessionSimulator sim(ScenarioFromJson(
      Walls(0.7, 1.6, 2, {{"disparity_pattern", {{"amplitude_raw", 4}, {"decay_per_raw", 0.004}}}}), "test"));
  const cv::Mat near = Excess(sim, SimRecording::kPlanar, 0), far = Excess(sim, SimRecording::kPlanar, 1);
  const cv::Rect inner(40, 40, 560, 400);
  cv::Mat a, b;
  near(inner).convertTo(a, CV_64F);
  far(inner).convertTo(b, CV_64F);
  cv::Scalar mean_a, sd_a, mean_b, sd_b;
  cv::meanStdDev(a, mean_a, sd_a);
  cv::meanStdDev(b, mean_b, sd_b);
  const double correlation = cv::mean((a - mean_a[0]).mul(b - mean_b[0]))[0] / (sd_a[0] * sd_b[0]);
  EXPECT_GT(correlation, 0.9) << "one fixed pattern at both distances";
  const auto& f = sim.scenario().depth;
  const double expected_ratio = std::exp(-0.004 * (f.RawFromDepth(1.6) - f.RawFromDepth(0.7)));
  EXPECT_NEAR(sd_b[0] / sd_a[0], expected_ratio, 0.1) << "the pattern shrinks as disparity falls";
}

TEST(CaptureTimeOffset, DepthSeesTheBoardWhereItWasLater) {
  const SessionSimulator sim(
      ScenarioFromJson(Boards(3, {{"capture_time_offset", {{"offset_s", 0.05}, {"board_speed_m_s", 0.2}}}}), "test"));
  double along_depth = 0;
  for (const auto& spec : sim.Frames(SimRecording::kDepthboard)) {
    const Eigen::Vector3d moved =
        spec.depth_target.ir_from_target.translation() - spec.colour_target.ir_from_target.translation();
    EXPECT_NEAR(moved.norm(), 0.2 * 0.05, 1e-9);
    along_depth = std::max(along_depth, std::abs(moved.z()) / moved.norm());
  }
  EXPECT_GT(along_depth, 0.3) << "each pose sways along its own direction, the depth axis too";
  // The depth image measures the board where it was later: at a board pixel
  // with ray r, a plane of normal n moved by m is (n.m) / (n.r) further along
  // the axis. Read back from the raw values through the depth model, against
  // the same session without the delay, over the board's inner pixels.
  const SessionSimulator still(ScenarioFromJson(Boards(3), "test"));
  const CameraModel& ir = sim.optics().ir;
  const auto& form = sim.scenario().depth;
  for (int i = 0; i < 3; ++i) {
    const SimFrameSpec& late = sim.Frames(SimRecording::kDepthboard)[static_cast<std::size_t>(i)];
    const SimFrameSpec& now = still.Frames(SimRecording::kDepthboard)[static_cast<std::size_t>(i)];
    ASSERT_TRUE(late.colour_target.ir_from_target.isApprox(now.colour_target.ir_from_target)) << "the same poses";
    const Eigen::Vector3d n = now.colour_target.ir_from_target.linear().col(2);
    const Eigen::Vector3d m =
        late.depth_target.ir_from_target.translation() - now.colour_target.ir_from_target.translation();
    const cv::Mat raw_late = Render(sim, SimRecording::kDepthboard, i),
                  raw_now = Render(still, SimRecording::kDepthboard, i);
    cv::Mat board = (sim.TrueDepth(late).surface == static_cast<int>(Surface::kTarget)) &
                    (still.TrueDepth(now).surface == static_cast<int>(Surface::kTarget));
    cv::erode(board, board, cv::Mat(), cv::Point(-1, -1), 4);  // away from the edges' mixed pixels
    double measured = 0, expected = 0;
    int pixels = 0;
    for (int v = 0; v < board.rows; ++v) {
      for (int u = 0; u < board.cols; ++u) {
        if (!board.at<std::uint8_t>(v, u) || Raw(raw_late, u, v) >= 2047 || Raw(raw_now, u, v) >= 2047) continue;
        const Eigen::Vector2d xy = ir.Undistort({u, v});
        expected += n.dot(m) / n.dot(Eigen::Vector3d(xy.x(), xy.y(), 1));
        measured += form.DepthFromRaw(Raw(raw_late, u, v)) - form.DepthFromRaw(Raw(raw_now, u, v));
        ++pixels;
      }
    }
    ASSERT_GT(pixels, 1000) << "pose " << i;
    EXPECT_NEAR(1000 * measured / pixels, 1000 * expected / pixels, 0.5) << "mm along the axis, pose " << i;
  }
}

TEST(MisalignedSnapshots, TiltsTheWallIntoARamp) {
  const auto ramp = [](const cv::Mat& raw) { return Raw(raw, 600, 240) - Raw(raw, 40, 240); };
  const SessionSimulator square(ScenarioFromJson(Walls(1.5, 1.5, 1), "test"));
  const SessionSimulator tilted(
      ScenarioFromJson(Walls(1.5, 1.5, 4, {{"misaligned_snapshots", {{"max_tilt_deg", 3}}}}), "test"));
  EXPECT_NEAR(ramp(Render(square, SimRecording::kPlanar, 0)), 0, 2);
  double largest = 0;
  for (int i = 0; i < 4; ++i) largest = std::max(largest, std::abs(ramp(Render(tilted, SimRecording::kPlanar, i))));
  EXPECT_GT(largest, 5);
}

TEST(BaseForm, TangentAndDisparityFormsInvertExactly) {
  for (const json& model : {json{{"form", "tangent"}}, json{{"form", "disparity"}}, json{{"form", "reciprocal"}}}) {
    const Scenario s = ScenarioFromJson({{"depth_model", model}}, "test");
    for (double z : {0.6, 1.0, 2.0, 3.5}) EXPECT_NEAR(s.depth.DepthFromRaw(s.depth.RawFromDepth(z)), z, 1e-9);
    EXPECT_GT(s.depth.RawFromDepth(2.0), s.depth.RawFromDepth(1.0)) << "raw grows with depth";
  }
  // Tangent truth differs from reciprocal truth by tens of mm somewhere in range: what a wrong base form shows.
  const Scenario tangent = ScenarioFromJson({{"depth_model", {{"form", "tangent"}}}}, "test");
  const Scenario reciprocal;
  double largest = 0;
  for (double r = 400; r < 1000; r += 10)
    largest = std::max(largest, std::abs(tangent.depth.DepthFromRaw(r) - reciprocal.depth.DepthFromRaw(r)));
  EXPECT_GT(largest, 0.01);
}

// The sensor's noise is in the raw value, so the residual is in raw units:
// fitting depth as a function of noisy raw values instead would be biased
// (errors in the regressor).
struct ReciprocalResidual {
  ReciprocalResidual(double raw, double z) : raw(raw), z(z) {}
  template <typename T>
  bool operator()(const T* a, const T* b, T* residual) const {
    residual[0] = T(raw) - (T(1.0 / z) - b[0]) / a[0];
    return true;
  }
  double raw, z;
};

TEST(Simulator, IdealPairsFitTheReciprocalFormBackWithinNoise) {
  // All effects off, noise on: pair each valid pixel's raw value with its true depth.
  json walls = Walls(0.6, 3.0, 10);
  walls["depth_model"]["raw_noise_sigma"] = 0.6;
  const SessionSimulator sim(ScenarioFromJson(walls, "test"));
  ceres::Problem problem;
  double a = -0.003, b = 3.0;
  int pairs = 0;
  for (const auto& spec : sim.Frames(SimRecording::kPlanar)) {
    const cv::Mat raw = sim.Render(SimRecording::kPlanar, spec).raw_depth;
    const cv::Mat z = sim.TrueDepth(spec).z_m;
    for (int v = 5; v < 480; v += 16) {
      for (int u = 5; u < 640; u += 16) {
        if (raw.at<std::uint16_t>(v, u) == 2047) continue;
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ReciprocalResidual, 1, 1, 1>(
                                     new ReciprocalResidual(raw.at<std::uint16_t>(v, u), z.at<double>(v, u))),
                                 nullptr, &a, &b);
        ++pairs;
      }
    }
  }
  ASSERT_GT(pairs, 5000);
  ceres::Solver::Options options;
  options.max_num_iterations = 100;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  ceres::Covariance::Options cov_options;
  ceres::Covariance covariance(cov_options);
  ASSERT_TRUE(covariance.Compute({{&a, &a}, {&b, &b}}, &problem));
  double var_a = 0, var_b = 0;
  covariance.GetCovarianceBlock(&a, &a, &var_a);
  covariance.GetCovarianceBlock(&b, &b, &var_b);
  // Ceres scales nothing: rescale the covariance by the residual variance.
  const double sigma2 = 2 * summary.final_cost / (pairs - 2);
  const Scenario truth;
  EXPECT_LT(std::abs(a - truth.depth.a), 3 * std::sqrt(var_a * sigma2)) << "a = " << a;
  EXPECT_LT(std::abs(b - truth.depth.b), 3 * std::sqrt(var_b * sigma2)) << "b = " << b;
}

TEST(Simulator, OpenCvFindsTheChessboardInNearlyEveryColourFrame) {
  const SessionSimulator sim((Scenario()));
  int found = 0, tried = 0;
  const Scenario& s = sim.scenario();
  for (const auto& spec : sim.Frames(SimRecording::kDepthboard)) {
    if (spec.context.seconds_into_pose > 0) continue;  // one frame per pose
    cv::Mat grey;
    cv::cvtColor(sim.Render(SimRecording::kDepthboard, spec).colour_rgb, grey, cv::COLOR_RGB2GRAY);
    std::vector<cv::Point2f> corners;
    found += cv::findChessboardCornersSB(grey, cv::Size(s.rig.squares_x - 1, s.rig.squares_y - 1), corners);
    ++tried;
  }
  EXPECT_GE(double(found) / tried, 0.95) << found << " of " << tried;
}

// --- bad scenario files ---

void ExpectRejected(const json& scenario, const std::string& names) {
  try {
    ScenarioFromJson(scenario, "scenario.json");
    FAIL() << "accepted: " << scenario.dump();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(names), std::string::npos) << e.what();
  }
}

TEST(BadScenario, UnknownEffect) {
  ExpectRejected({{"effects", {{"lens_flare", json::object()}}}}, "unknown effect \"lens_flare\"");
}
TEST(BadScenario, MissingEffectParameter) {
  ExpectRejected({{"effects", {{"thermal_drift", {{"amplitude_raw", 3}}}}}},
                 "effects.thermal_drift: missing required key \"time_constant_s\"");
}
TEST(BadScenario, OutOfRangeEffectParameter) {
  ExpectRejected({{"effects", {{"depth_grid_offset", {{"dx_px", 40}, {"dy_px", 0}}}}}},
                 "effects.depth_grid_offset.dx_px");
}
TEST(BadScenario, UnknownEffectKey) {
  ExpectRejected({{"effects", {{"albedo_bias", {{"dark_bias_raw", 3}, {"colour", 2}}}}}}, "unknown key \"colour\"");
}
TEST(BadScenario, UnknownBaseForm) { ExpectRejected({{"depth_model", {{"form", "cubic"}}}}, "depth_model.form"); }
TEST(BadScenario, KeyOfAnotherBaseForm) {
  ExpectRejected({{"depth_model", {{"form", "tangent"}, {"a", -0.003}}}}, "unknown key \"a\"");
}

TEST(SimEffectCatalogue, EveryEffectIsRegisteredWithADocLine) {
  std::vector<std::string> names;
  for (const auto& info : SimEffectCatalogue()) {
    names.push_back(info.name);
    EXPECT_FALSE(info.doc.empty()) << info.name;
  }
  for (const char* expected : {"radial_billow", "disparity_pattern", "depth_grid_offset", "thermal_drift",
                               "capture_time_offset", "albedo_bias", "misaligned_snapshots"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
  }
}

}  // namespace
}  // namespace speckle::sim
