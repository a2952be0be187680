// The depth model as a composition, formula effects, and the diagnosis on
// synthetic samples drawn from a known model (fast; the simulator-session
// hunts are in hunt_test.cc).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <random>
#include <set>

#include "apps/model_summary.h"
#include "lab/diagnosis/model_diagnosis.h"
#include "lab/diagnosis/verdict.h"
#include "lab/diagnosis/verdict_text.h"
#include "lab/fit/tangent_form_manifold.h"
#include "lab/model_spec.h"
#include "model/depth_model.h"
#include "model/formula_effect.h"
#include "schemas/errors.h"

namespace speckle {
namespace {

using nlohmann::json;

model::EffectSpec Named(const std::string& name) {
  model::EffectSpec e;
  e.name = name;
  return e;
}

// 30 still poses of 3 frames, 40 board points each, over 15 minutes; raw
// values from the reciprocal truth plus `extra` plus noise (per frame and per
// sample).
// The verdict as the apps write it for a session named S.
std::string Words(const Diagnosis& d) { return VerdictText(d, "S"); }

std::vector<PairedSample> Synthetic(std::uint64_t seed, const std::function<double(const PairedSample&)>& extra) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0, 1);
  std::uniform_real_distribution<double> uniform(0, 1);
  const double a = -0.0027681, b = 3.0163;
  std::vector<PairedSample> samples;
  int frame = 0;
  for (int pose = 0; pose < 30; ++pose) {
    const double z0 = 0.6 + 0.9 * uniform(rng), tilt = 0.3 * (uniform(rng) - 0.5);
    const double cu = 150 + 340 * uniform(rng), cv = 120 + 240 * uniform(rng);
    const double vu = 20 * noise(rng), vv = 20 * noise(rng);
    for (int f = 0; f < 3; ++f, ++frame) {
      const double frame_error = 0.15 * noise(rng);  // a colour pose's depth error, in raw units
      for (int k = 0; k < 40; ++k) {
        PairedSample s;
        s.frame = frame, s.pose = pose, s.board_point = k;
        s.time_s = pose * 30 + f / 30.0;
        s.u = cu + (k % 8 - 3.5) * 14, s.v = cv + (k / 8 - 2) * 14;
        s.x = (s.u - 320) / 580, s.y = (s.v - 240) / 580;
        s.depth_m = z0 * (1 + tilt * s.x);
        const double base = (1 / s.depth_m - b) / a;
        s.gradient_u = tilt * 1.5, s.gradient_v = 0.2;
        s.velocity_u = vu, s.velocity_v = vv;
        s.raw_rate = vu;  // a swaying board: tens of raw units per second
        s.albedo = k % 3 == 0 ? 0.0 : (k % 3 == 1 ? 1.0 : 0.5);
        s.raw = base;
        s.raw = base + extra(s) + frame_error + 0.3 * noise(rng);
        samples.push_back(s);
      }
    }
  }
  return samples;
}

DepthFit Fit(const model::ModelDefinition& definition, const std::vector<PairedSample>& samples) {
  auto fit = RunDepthModelFit(DepthFitOptions{}, definition, samples);
  EXPECT_TRUE(Accepted(fit)) << (Accepted(fit) ? "" : std::get<Rejection>(fit).reason);
  return std::get<DepthFit>(fit);
}

TEST(EffectCatalogue, EveryDomainEffectIsThereWithDocAndSaneParameters) {
  std::set<std::string> names;
  for (const auto& info : model::EffectCatalogue()) {
    names.insert(info.name);
    EXPECT_FALSE(info.doc.empty()) << info.name;
    const auto effect = info.create();
    EXPECT_FALSE(effect->CovariatesRead().empty()) << info.name;
    std::vector<double> initial;
    for (const auto& p : effect->Parameters()) {
      EXPECT_LE(p.lower, p.initial) << info.name << "." << p.name;
      EXPECT_LE(p.initial, p.upper) << info.name << "." << p.name;
      initial.push_back(p.initial);
    }
    model::Covariates c;
    c.raw = 800, c.u = 100, c.v = 400, c.x = -0.4, c.y = 0.3, c.time_s = 60, c.albedo = 0.2;
    EXPECT_TRUE(std::isfinite(effect->RawOffset(initial.data(), c))) << info.name;
  }
  for (const char* name : {"radial_billow", "disparity_pattern", "depth_grid_offset", "thermal_drift",
                           "capture_time_offset", "albedo_bias", "spatial_field"}) {
    EXPECT_TRUE(names.count(name)) << name;
  }
}

TEST(BaseForms, FitWithinTheResidualsJetSize) {
  for (const auto& info : model::BaseForms())
    EXPECT_LE(static_cast<int>(info.parameters.size()), model::kMaxBaseParameters) << info.name;
}

// Steps in (k c, k (pi/2 - b), c^2) come back to Magnenat's (c, k, b):
// Plus undoes Minus, and the two Jacobians are each other's inverse.
TEST(BaseForms, TangentStepsAreACoordinateChange) {
  const TangentFormManifold manifold;
  const double x[3] = {0.15257, 2431.3, 1.12}, y[3] = {0.09, 3100.0, 1.3};
  double step[3], back[3];
  ASSERT_TRUE(manifold.Minus(y, x, step));
  ASSERT_TRUE(manifold.Plus(x, step, back));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(back[i], y[i], 1e-9 * std::abs(y[i])) << i;
  double plus[9], minus[9];
  ASSERT_TRUE(manifold.PlusJacobian(x, plus));
  ASSERT_TRUE(manifold.MinusJacobian(x, minus));
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double product = 0;
      for (int k = 0; k < 3; ++k) product += minus[i * 3 + k] * plus[k * 3 + j];
      EXPECT_NEAR(product, i == j ? 1.0 : 0.0, 1e-9) << i << ", " << j;
    }
  const double far[3] = {0, 0, -100};  // q at its floor: c at 0.1 mm, k and b finite
  ASSERT_TRUE(manifold.Plus(x, far, back));
  EXPECT_NEAR(back[0], std::sqrt(TangentFormManifold::kMinQ), 1e-12);
  EXPECT_TRUE(std::isfinite(back[1]) && std::isfinite(back[2]));
}

int Iterations(const std::string& solver_report) {
  const auto at = solver_report.find("Iterations: ");
  return at == std::string::npos ? -1 : std::stoi(solver_report.substr(at + 12));
}

// On a sensor the reciprocal form describes, the tangent form's best fit is
// at the end of its valley (c -> 0). Stepping in Magnenat's coordinates it
// ran to the 100-iteration limit; in the manifold's it converges, and
// predicts the held-out poses as well as the reciprocal form does.
TEST(BaseForms, TheTangentFormConvergesOnAReciprocalSensor) {
  // A sensor the reciprocal form describes, and one a little past it (raw
  // curving the other way in 1/z: the tangent form's best fit then sits at
  // the reciprocal limit, where clamping q at its floor crept for 78
  // iterations and stopped 11 % above the reciprocal form's held-out error;
  // see TangentFormManifold).
  for (double past : {0.0, -2.0}) {
    const auto samples = Synthetic(3, [&](const PairedSample& s) { return past / std::pow(s.depth_m, 3); });
    const DepthFit reciprocal = Fit({model::BaseForm::kReciprocal, {}}, samples);
    const DepthFit tangent = Fit({model::BaseForm::kTangent, {}}, samples);
    EXPECT_TRUE(tangent.converged) << tangent.solver_report;
    EXPECT_LE(Iterations(tangent.solver_report), 12) << past << ": " << tangent.solver_report;
    EXPECT_LT(tangent.held_out_raw.rms, 1.01 * reciprocal.held_out_raw.rms) << past;
    for (double p : tangent.parameters) EXPECT_TRUE(std::isfinite(p));
  }
}

TEST(EffectCatalogue, GradientsMatchFiniteDifferences) {
  for (const auto& info : model::EffectCatalogue()) {
    const auto effect = info.create();
    std::vector<double> p;
    for (const auto& q : effect->Parameters())
      p.push_back(q.initial + 0.01 * (q.upper - q.lower > 1e6 ? 1 : q.upper - q.lower) * 0.3);
    // Move each B-spline control differently, so a gradient entry sent to the wrong control shows.
    for (std::size_t i = 0; i < p.size(); ++i) p[i] += 1e-3 * std::sin(1.0 + static_cast<double>(i));
    model::Covariates c;
    c.raw = 750, c.u = 610, c.v = 461, c.x = 0.3, c.y = -0.2, c.time_s = 100, c.gradient_u = 1.2, c.gradient_v = -0.7;
    c.velocity_u = 30, c.velocity_v = -10, c.albedo = 0.1, c.raw_rate = 25;
    std::vector<double> gradient(p.size(), std::nan(""));
    const double value = effect->RawOffset(p.data(), c, gradient.data());
    EXPECT_NEAR(value, effect->RawOffset(p.data(), c), 1e-9) << info.name;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double h = 1e-6 * std::max(1.0, std::abs(p[i]));
      std::vector<double> plus = p, minus = p;
      plus[i] += h, minus[i] -= h;
      const double numeric = (effect->RawOffset(plus.data(), c) - effect->RawOffset(minus.data(), c)) / (2 * h);
      EXPECT_NEAR(gradient[i], numeric, 1e-4 * std::max(1.0, std::abs(numeric))) << info.name << " parameter " << i;
    }
  }
}

TEST(DepthModel, FrozenEffectKeepsItsInitialValues) {
  const auto samples = Synthetic(1, [](const PairedSample& s) { return -5 * (1 - std::exp(-s.time_s / 400)); });
  model::ModelDefinition definition{
      model::BaseForm::kReciprocal,
      {model::EffectSpecFromJson(json{{"name", "thermal_drift"},
                                      {"frozen", true},
                                      {"initial", {{"amplitude", -2.0}, {"time_constant", 100.0}}}},
                                 "test")}};
  const DepthFit fit = Fit(definition, samples);
  EXPECT_EQ(fit.parameters[2], -2.0);
  EXPECT_EQ(fit.parameters[3], 100.0);
  EXPECT_EQ(fit.sigma[2], 0.0);
  // The summary says it was held, where it printed "± 0" as though exact.
  ModelLab lab;
  lab.fits.push_back({"reciprocal + thermal_drift", false, fit});
  lab.chosen = 0;
  const std::string summary = ModelSummary(lab);
  EXPECT_NE(summary.find("thermal_drift.amplitude = -2 (held, not fitted)"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("± 0 "), std::string::npos) << summary;
}

TEST(DepthModel, ThermalDriftIsRecoveredWithinItsUncertainty) {
  const auto samples = Synthetic(2, [](const PairedSample& s) { return -6 * (1 - std::exp(-s.time_s / 400)); });
  const DepthFit fit = Fit({model::BaseForm::kReciprocal, {Named("thermal_drift")}}, samples);
  EXPECT_NEAR(fit.parameters[2], -6, 3 * fit.sigma[2]);
  EXPECT_NEAR(fit.parameters[3], 400, 3 * fit.sigma[3]);
  EXPECT_LT(fit.sigma[2], 1.0);
}

// The raw value read while the board moved is the one of `delay` later: the
// fit recovers the delay from the raw rate, and finds none on still boards.
TEST(DepthModel, CaptureTimeDelayIsRecoveredFromTheRawRate) {
  const double delay = 0.033;
  const auto samples = Synthetic(4, [&](const PairedSample& s) { return delay * s.raw_rate; });
  const DepthFit fit = Fit({model::BaseForm::kReciprocal, {Named("capture_time_offset")}}, samples);
  EXPECT_NEAR(fit.parameters[2], delay, 3 * fit.sigma[2]);
  EXPECT_LT(fit.sigma[2], 0.005);
  const DepthFit still = Fit({model::BaseForm::kReciprocal, {Named("capture_time_offset")}},
                             Synthetic(4, [](const PairedSample&) { return 0.0; }));
  EXPECT_NEAR(still.parameters[2], 0, 3 * still.sigma[2]);
}

TEST(Diagnosis, NamesTheMissingEffectAndItsCovariate) {
  const auto samples = Synthetic(3, [](const PairedSample& s) { return 3 * (1 - s.albedo); });
  const DepthFit fit = Fit({model::BaseForm::kReciprocal, {}}, samples);
  const Diagnosis d = RunModelDiagnosis({}, samples, fit);
  EXPECT_FALSE(d.complete);
  ASSERT_TRUE(d.recommended.has_value()) << Words(d);
  EXPECT_EQ(*d.recommended, "albedo_bias") << Words(d);
  EXPECT_EQ(d.covariates.front().covariate, "albedo") << Words(d);
  EXPECT_NE(Words(d).find("refit S --add-effect albedo_bias"), std::string::npos) << Words(d);
  // The stage gives the command as a part of its own, for the apps to write.
  EXPECT_EQ(d.conclusion, Conclusion::kAddEffect);
  const auto command = std::find_if(d.verdict.begin(), d.verdict.end(),
                                    [](const VerdictPart& p) { return p.kind != VerdictPart::Kind::kWords; });
  ASSERT_NE(command, d.verdict.end());
  EXPECT_EQ(command->kind, VerdictPart::Kind::kAddEffect);
  EXPECT_EQ(command->argument, "albedo_bias");
  EXPECT_EQ(NextStepsJson(d, "S")[0]["command"], "refit S --add-effect albedo_bias");
  for (const auto& part : d.verdict) EXPECT_EQ(part.argument.find("refit"), std::string::npos) << part.argument;
  // Added, the held-out error comes to the floor and nothing more is recommended.
  const DepthFit fixed = Fit({model::BaseForm::kReciprocal, {Named("albedo_bias")}}, samples);
  const Diagnosis after = RunModelDiagnosis({}, samples, fixed);
  EXPECT_TRUE(after.complete) << Words(after);
  EXPECT_FALSE(after.recommended.has_value());
  EXPECT_LT(after.ratio_to_floor, 1.15);
}

TEST(Diagnosis, TheFloorCountsTheUndistortionGridsStandardError) {
  // Undistorted samples carry the grid's estimation error, which no depth
  // model removes: in wide-angle rooms it left the board model 1.34x a floor
  // that did not count it.
  const auto samples = Synthetic(3, [](const PairedSample&) { return 0.0; });
  const DepthFit fit = Fit({model::BaseForm::kReciprocal, {}}, samples);
  const Diagnosis plain = RunModelDiagnosis({}, samples, fit);
  const Diagnosis gridded = RunModelDiagnosis({}, samples, fit, {}, std::vector<double>(samples.size(), 0.3));
  EXPECT_LT(plain.floor.grid_raw, 0) << "no grid, no part";
  EXPECT_NEAR(gridded.floor.grid_raw, 0.3, 1e-9);
  EXPECT_NEAR(gridded.floor.floor_raw, std::hypot(plain.floor.floor_raw, 0.3), 1e-9);
  EXPECT_NE(gridded.floor.source.find("undistortion grid"), std::string::npos) << gridded.floor.source;
}

// One frame a pose (many users' sessions): no consecutive frames, so the
// sensor's part comes from neighbouring corners of each frame, whose
// difference cancels the frame's colour pose error and the model's smooth
// error. It once fell back to one pixel's rounding (0.289 raw) for samples
// that average 25 pixels, and wide-angle rooms passed at 0.53x that floor.
TEST(Diagnosis, OneFrameAPoseTakesTheSensorsPartFromNeighbouringCorners) {
  std::vector<PairedSample> all = Synthetic(4, [](const PairedSample&s) { return 0.004 * (s.u - 320); }), single;
  for (const auto& s : all)
    if (s.frame % 3 == 0) single.push_back(s);
  const Diagnosis d = RunModelDiagnosis({}, single, Fit({model::BaseForm::kReciprocal, {}}, single));
  EXPECT_LT(d.floor.consecutive_frames_raw, 0);
  EXPECT_NEAR(d.floor.neighbour_corners_raw, 0.3, 0.03) << "the samples' own noise";
  EXPECT_EQ(d.floor.sensor_raw, d.floor.neighbour_corners_raw);
  EXPECT_NE(d.floor.source.find("neighbouring corners"), std::string::npos) << d.floor.source;

  // With consecutive frames, they are what the floor uses; the corners,
  // blind to the frames' own colour pose errors (0.15 raw), agree with the
  // sensor's noise alone.
  const Diagnosis three = RunModelDiagnosis({}, all, Fit({model::BaseForm::kReciprocal, {}}, all));
  EXPECT_NEAR(three.floor.consecutive_frames_raw, std::hypot(0.3, 0.15), 0.03);
  EXPECT_EQ(three.floor.sensor_raw, three.floor.consecutive_frames_raw);
  EXPECT_NEAR(three.floor.neighbour_corners_raw, 0.3, 0.03);

  for (auto& s : single) s.point = SamplePoint::kSquareCentre;  // opposite albedos side by side
  const Diagnosis centres = RunModelDiagnosis({}, single, Fit({model::BaseForm::kReciprocal, {}}, single));
  EXPECT_LT(centres.floor.neighbour_corners_raw, 0);
  EXPECT_EQ(centres.floor.sensor_raw, centres.floor.quantization_raw);
}

// Each command part is written out for the session: a pair as one refit
// adding both effects.
TEST(VerdictText, WritesEachCommandForTheSession) {
  Diagnosis d;
  d.verdict = {{VerdictPart::Kind::kWords, "adding a helps — run: "},
               {VerdictPart::Kind::kAddEffect, "thermal_drift"},
               {VerdictPart::Kind::kWords, ". With b as well: run "},
               {VerdictPart::Kind::kAddEffect, "thermal_drift albedo_bias"},
               {VerdictPart::Kind::kWords, "; or "},
               {VerdictPart::Kind::kBaseForm, "tangent"}};
  EXPECT_EQ(VerdictText(d, "runs/s"),
            "adding a helps — run: refit runs/s --add-effect thermal_drift. With b as well: run refit runs/s "
            "--add-effect thermal_drift --add-effect albedo_bias; or refit runs/s --model MODEL.json with "
            "\"base_form\": \"tangent\"");
  EXPECT_EQ(VerdictText(d, "runs/s", "build/refit").rfind("adding a helps — run: build/refit runs/s --add", 0), 0u);
  const auto steps = NextStepsJson(d, "runs/s", "build/refit");
  ASSERT_EQ(steps.size(), 3u);
  EXPECT_EQ(steps[2]["command"], "build/refit runs/s --model MODEL.json with \"base_form\": \"tangent\"");
  EXPECT_EQ(steps[1]["kind"], "add_effect");
  EXPECT_EQ(steps[1]["argument"], "thermal_drift albedo_bias");
  EXPECT_EQ(steps[2]["kind"], "base_form");
}

// A millimetre sensor's verdict speaks of the millimetres it reads, never of
// raw disparity it does not have.
TEST(Diagnosis, AMillimetreSensorsVerdictIsInTheMillimetresItReads) {
  const auto samples = Synthetic(3, [](const PairedSample& s) { return 3 * (1 - s.albedo); });
  DiagnosisOptions options;
  options.millimetre_readings = true;
  const Diagnosis d = RunModelDiagnosis(options, samples, Fit({model::BaseForm::kReciprocal, {}}, samples));
  const std::string words = Words(d);
  EXPECT_NE(words.find(" mm read ("), std::string::npos) << words;
  EXPECT_EQ(words.find(" raw"), std::string::npos) << words;
}

TEST(Diagnosis, RecommendsNothingForACompleteModelOnNineOfTenSeeds) {
  int quiet = 0;
  for (std::uint64_t seed = 10; seed < 20; ++seed) {
    const auto samples = Synthetic(seed, [](const PairedSample&) { return 0.0; });
    const Diagnosis d = RunModelDiagnosis({}, samples, Fit({model::BaseForm::kReciprocal, {}}, samples));
    quiet += !d.recommended.has_value();
  }
  EXPECT_GE(quiet, 9);
}

// A per-pixel pattern seen by 30 small board patches: the catalogue pattern
// fits every patch to the floor, but a patch held out lies where few or no
// other patches measured the pattern. The remedy is more poses, and the
// diagnosis says so, naming the cells few poses reach.
TEST(Diagnosis, AModelThePosesDoNotPinDownAsksForMorePosesWhereFewReach) {
  const auto samples = Synthetic(6, [](const PairedSample& s) { return 3 * std::sin(s.u / 40) * std::cos(s.v / 30); });
  const DepthFit fit = Fit({model::BaseForm::kReciprocal, {Named("disparity_pattern")}}, samples);
  const Diagnosis d = RunModelDiagnosis({}, samples, fit);
  std::printf("in-sample %.3f, held out %.3f, floor %.3f raw\n%s\n", d.coverage.in_sample_rms, d.held_out_rms,
              d.floor.floor_raw, Words(d).c_str());
  EXPECT_FALSE(d.complete);
  EXPECT_TRUE(d.coverage.under_determined);
  EXPECT_FALSE(d.recommended.has_value()) << Words(d);
  EXPECT_EQ(d.coverage.poses, 30);
  EXPECT_EQ(d.coverage.parameters, static_cast<int>(fit.parameters.size()));
  ASSERT_FALSE(d.coverage.sparse.empty());
  EXPECT_TRUE(std::is_sorted(d.coverage.sparse.begin(), d.coverage.sparse.end(), [](const auto& a, const auto& b) {
    return a.poses.size() < b.poses.size();
  })) << "the cells fewest poses reach come first";
  // Each sparse cell lists exactly the poses with samples in it.
  for (const auto& cell : d.coverage.sparse) {
    std::set<int> inside;
    for (const auto& s : samples)
      if (s.u >= cell.u0 && s.u < cell.u1 && s.v >= cell.v0 && s.v < cell.v1) inside.insert(s.pose);
    EXPECT_EQ(std::vector<int>(inside.begin(), inside.end()), cell.poses)
        << "cell at u " << cell.u0 << ", v " << cell.v0;
    EXPECT_LT(static_cast<int>(cell.poses.size()), d.coverage.min_poses);
  }
  const auto& first = d.coverage.sparse.front();
  EXPECT_TRUE(d.coverage.ModelReadsImage());
  EXPECT_NE(Words(d).find("Record more board poses"), std::string::npos) << Words(d);
  EXPECT_EQ(d.conclusion, Conclusion::kMorePoses);
  EXPECT_NE(Words(d).find(fmt::format("u {}-{} px, v {}-{} px", first.u0, first.u1, first.v0, first.v1)),
            std::string::npos)
      << Words(d);
  // Without the pattern, a complete few-parameter model: in-sample and held
  // out agree, and nothing asks for more poses.
  const auto clean = Synthetic(6, [](const PairedSample&) { return 0.0; });
  const Diagnosis plain = RunModelDiagnosis({}, clean, Fit({model::BaseForm::kReciprocal, {}}, clean));
  EXPECT_TRUE(plain.complete) << Words(plain);
  EXPECT_FALSE(plain.coverage.under_determined);
  // The grid spans the depth image, also where no board reached (these
  // boards stop short of u = 560): 8 x 6 cells of 80 px, the empty ones
  // counted as empty.
  double u_max = 0;
  for (const auto& s : clean) u_max = std::max(u_max, s.u);
  ASSERT_LT(u_max, 560);
  EXPECT_EQ(plain.coverage.cells_u, 8);
  EXPECT_EQ(plain.coverage.poses_per_cell.size(), 48u);
  EXPECT_GE(plain.coverage.empty_cells, 6) << "the right-hand column has no board";
}

// A toolbox's frame folder has no timestamps: every sample's time is 0, as
// in Herrera's set. Time is then neither a covariate nor read by a candidate:
// before, the time profile's groups followed the poses' order, and Herrera's
// refit was told its residuals "vary with time" (p = 0.001) and given a
// formula in time_s that could fit nothing.
TEST(Diagnosis, ACovariateThatNeverVariesIsNeitherNamedNorTried) {
  auto samples = Synthetic(3, [](const PairedSample& s) { return 0.5 * std::sin(s.pose); });
  for (auto& s : samples) s.time_s = 0, s.albedo = 0.5;
  const Diagnosis d = RunModelDiagnosis({}, samples, Fit({model::BaseForm::kReciprocal, {}}, samples));
  for (const auto& c : d.covariates) {
    EXPECT_NE(c.covariate, "time") << c.level;
    EXPECT_NE(c.covariate, "albedo") << c.level;
  }
  std::set<std::string> tried;
  for (const auto& c : d.candidates) tried.insert(c.name);
  EXPECT_FALSE(tried.count("thermal_drift")) << Words(d);
  EXPECT_FALSE(tried.count("albedo_bias")) << Words(d);
  EXPECT_TRUE(tried.count("capture_time_offset")) << "raw_rate varies: " << Words(d);
  EXPECT_EQ(Words(d).find("time_s"), std::string::npos) << Words(d);
  EXPECT_EQ(Words(d).find("with time"), std::string::npos) << Words(d);
}

// A drift whose time constant 20 poses do not pin down (hunt
// thermal_drift_mm seed 6: amplitude -4 +- 18 raw) is not helped by poses
// where the image is sparse: the words name the drift's covariates instead
// of image cells, which they named before.
TEST(Diagnosis, MorePosesForAnEffectBlindToTheImageNamesWhatItReadsNotImageCells) {
  Diagnosis d;
  d.floor.floor_raw = 0.7;
  d.held_out_rms = 0.95;
  d.ratio_to_floor = d.held_out_rms / d.floor.floor_raw;
  d.coverage.under_determined = true;
  d.coverage.in_sample_rms = 0.77;
  d.coverage.poses = 20;
  d.coverage.parameters = 4;
  d.coverage.min_poses = 3;
  d.coverage.sparse.push_back({400, 0, 480, 80, {19}});
  d.coverage.model_reads = {"raw", "time_s"};
  ConcludeDiagnosis({}, d);
  EXPECT_EQ(d.conclusion, Conclusion::kMorePoses);
  EXPECT_NE(Words(d).find("spread over what its effects read (raw, time_s)"), std::string::npos) << Words(d);
  EXPECT_EQ(Words(d).find("u 400-480 px"), std::string::npos) << Words(d);
  d.coverage.model_reads.insert("u");
  ConcludeDiagnosis({}, d);
  EXPECT_NE(Words(d).find("poses reach the image: u 400-480 px, v 0-80 px (pose 19)"), std::string::npos) << Words(d);
}

// "Complete" under a floor that is mostly the cameras' uncertainty says how
// little that means (the wide-angle room without an IR chessboard: cameras
// 0.41 of a 0.49 raw floor); under a floor of the sensor's own noise it does
// not.
TEST(Diagnosis, CompleteUnderTheCamerasUncertaintySaysTheCamerasLimitIt) {
  Diagnosis d;
  d.floor.floor_raw = 0.488;
  d.floor.cameras_raw = 0.414;
  d.held_out_rms = 0.264;
  d.ratio_to_floor = d.held_out_rms / d.floor.floor_raw;
  d.complete = true;
  ConcludeDiagnosis({}, d);
  EXPECT_EQ(d.conclusion, Conclusion::kComplete);
  EXPECT_NE(Words(d).find("as good as the cameras allow"), std::string::npos) << Words(d);
  EXPECT_NE(Words(d).find("0.414 of 0.488 raw"), std::string::npos) << Words(d);
  d.floor.cameras_raw = 0.2;
  ConcludeDiagnosis({}, d);
  EXPECT_EQ(Words(d).find("cameras allow"), std::string::npos) << Words(d);
  EXPECT_NE(Words(d).find("The model is complete"), std::string::npos) << Words(d);
}

// The true depths from a miscalibrated camera: tilted by `tilt` across the
// image, as an IR principal point that is off tilts them through the
// extrinsics. The perturbations hold that camera input's one-sigma tilt
// (sigma_tilt) and a one-sigma scale, as calibration_run.cc writes them.
struct TiltedTruth {
  std::vector<PairedSample> samples;
  DepthPerturbations perturbations;
};
TiltedTruth Tilted(double tilt, double sigma_tilt) {
  TiltedTruth t;
  t.samples = Synthetic(5, [](const PairedSample&) { return 0.0; });
  t.perturbations.resize(2);
  for (auto& s : t.samples) {
    s.depth_m *= 1 + tilt * s.x;
    t.perturbations[0].push_back(s.depth_m * (1 + sigma_tilt * s.x));
    t.perturbations[1].push_back(s.depth_m * 1.001);
  }
  return t;
}

// A raw session is not offered the millimetre form of the warm-up drift
// (effects with kUnits "millimetre"); the millimetre side is
// HiddenEffectInMillimetres in tests/hunt_test.cc.
TEST(Diagnosis, TriesOnlyTheEffectsOfTheSessionsUnits) {
  const auto samples = Synthetic(5, [](const PairedSample&) { return 0.0; });
  const Diagnosis d = RunModelDiagnosis({}, samples, Fit({model::BaseForm::kReciprocal, {}}, samples));
  std::set<std::string> tried;
  for (const auto& c : d.candidates) tried.insert(c.name);
  EXPECT_TRUE(tried.count("thermal_drift")) << Words(d);
  EXPECT_FALSE(tried.count("thermal_drift_mm")) << Words(d);
}

TEST(Diagnosis, StructureTheCamerasUncertaintyCanLeaveIsNotAMissingEffect) {
  // 1.5 sigma of tilt: depth_grid_offset would fit it, but so do the cameras.
  const TiltedTruth within = Tilted(0.006, 0.004);
  const DepthFit fit = Fit({model::BaseForm::kReciprocal, {}}, within.samples);
  const Diagnosis blind = RunModelDiagnosis({}, within.samples, fit);
  ASSERT_TRUE(blind.recommended.has_value()) << "without the cameras' uncertainty the tilt looks like an effect";
  const Diagnosis d = RunModelDiagnosis({}, within.samples, fit, within.perturbations);
  EXPECT_FALSE(d.recommended.has_value()) << Words(d);
  EXPECT_NE(Words(d).find("calibration uncertainty"), std::string::npos) << Words(d);
  ASSERT_EQ(d.camera_shift_sigma.size(), 2u);
  EXPECT_NEAR(d.camera_shift_sigma[0], -1.5, 0.3) << "the fit moves the camera back by the tilt";
  ASSERT_TRUE(d.cameras_free_held_out_rms.has_value());
  EXPECT_LT(*d.cameras_free_held_out_rms, 0.9 * d.held_out_rms);
  // Five sigma of tilt: the cameras may move three, the rest is an effect.
  const TiltedTruth beyond = Tilted(0.02, 0.004);
  const Diagnosis far = RunModelDiagnosis({}, beyond.samples, Fit({model::BaseForm::kReciprocal, {}}, beyond.samples),
                                          beyond.perturbations);
  ASSERT_TRUE(far.recommended.has_value()) << Words(far);
  EXPECT_EQ(*far.recommended, "depth_grid_offset") << Words(far);
}

TEST(DepthFit, CameraFreedomMovesTheCamerasWithinTheirBounds) {
  const TiltedTruth t = Tilted(0.006, 0.004);
  DepthFitOptions options;
  options.camera_freedom_sigma = 3;
  const auto free_fit = RunDepthModelFit(options, {model::BaseForm::kReciprocal, {}}, t.samples, t.perturbations);
  ASSERT_TRUE(Accepted(free_fit));
  const DepthFit& f = std::get<DepthFit>(free_fit);
  EXPECT_NEAR(f.camera_shift_sigma[0], -1.5, 0.3);
  EXPECT_LT(f.held_out_raw.rms, 0.9 * Fit({model::BaseForm::kReciprocal, {}}, t.samples).held_out_raw.rms);
  options.camera_freedom_sigma = 0.5;  // too little freedom: held at the bound
  const auto bounded = RunDepthModelFit(options, {model::BaseForm::kReciprocal, {}}, t.samples, t.perturbations);
  ASSERT_TRUE(Accepted(bounded));
  EXPECT_NEAR(std::get<DepthFit>(bounded).camera_shift_sigma[0], -0.5, 1e-6);
}

// A sensor far from the nominal Kinect (a wide-angle adapter: 1/z = -0.00417
// r + 4.51) with five camera directions free: the folds start from the
// model's initial values, and the shifts must not run to their bounds before
// the base form comes near (they did: 11 raw held out where the fit without
// the cameras had 0.25, and every candidate looked 98 % better than it).
TEST(DepthFit, CameraFreedomFarFromTheNominalSensorStillConverges) {
  std::vector<PairedSample> samples = Synthetic(7, [](const PairedSample&) { return 0.0; });
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0, 0.3);
  DepthPerturbations perturbations(5);
  for (auto& s : samples) {
    s.raw = (1 / s.depth_m - 4.51) / -0.00417 + noise(rng);
    for (int k = 0; k < 5; ++k)
      perturbations[static_cast<std::size_t>(k)].push_back(s.depth_m *
                                                           (1 + 0.003 * (k % 2 ? s.x : 1) + 0.001 * k * s.y));
  }
  const DepthFit fixed = Fit({model::BaseForm::kReciprocal, {}}, samples);
  DepthFitOptions options;
  options.camera_freedom_sigma = 3;
  const auto free_fit = RunDepthModelFit(options, {model::BaseForm::kReciprocal, {}}, samples, perturbations);
  ASSERT_TRUE(Accepted(free_fit));
  const DepthFit& f = std::get<DepthFit>(free_fit);
  EXPECT_LT(f.held_out_raw.rms, 1.1 * fixed.held_out_raw.rms) << f.solver_report;
  for (double shift : f.camera_shift_sigma) EXPECT_LT(std::abs(shift), 2.9) << "a shift ran to its bound";
}

// A driver's millimetres are noisier far away by z^2 (lab/fit/fit_options.h):
// the fit must be the least squares of residuals weighted by (1 m / z)^2,
// here against its closed form (linear_mm is linear in mm = (z - b) / a),
// and the unweighted one without the option. The far poses carry a bias
// the weights must discount.
TEST(DepthFit, MillimetreReadingsAreWeightedByDepthSquared) {
  std::vector<PairedSample> samples;
  for (int pose = 0; pose < 20; ++pose) {
    const double z0 = 0.6 + 0.12 * pose;
    for (int k = 0; k < 20; ++k) {
      PairedSample s;
      s.frame = pose, s.pose = pose, s.board_point = k;
      s.depth_m = z0 + 0.01 * k;
      const double error_mm = (k % 2 ? 1.0 : -1.0) * 3 * s.depth_m * s.depth_m + (z0 > 2 ? 8.0 : 0.0);
      s.raw = (s.depth_m + 0.0098) * 1020 + error_mm;
      samples.push_back(s);
    }
  }
  for (bool weighted : {false, true}) {
    // mm = alpha z + beta, each row weighted by w = (1000 / mm)^2 or 1.
    Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
    Eigen::Vector2d right = Eigen::Vector2d::Zero();
    for (const auto& s : samples) {
      const double w = weighted ? std::pow(1000 / s.raw, 2) : 1;
      const Eigen::Vector2d row(w * s.depth_m, w);
      normal += row * row.transpose(), right += row * (w * s.raw);
    }
    const Eigen::Vector2d closed = normal.ldlt().solve(right);
    DepthFitOptions options;
    options.millimetre_readings = weighted;
    const auto fit = RunDepthModelFit(options, {model::BaseForm::kLinearMm, {}}, samples);
    ASSERT_TRUE(Accepted(fit));
    const std::vector<double>& p = std::get<DepthFit>(fit).parameters;  // z = a mm + b
    EXPECT_NEAR(p[0], 1 / closed[0], 1e-9 * std::abs(p[0])) << "weighted " << weighted;
    EXPECT_NEAR(p[1], -closed[1] / closed[0], 1e-6) << "weighted " << weighted;
  }
}

// The Huber loss weighs each sample by its own residual: the fit is the
// fixed point of iteratively reweighted least squares with weights
// min(1, scale / |r|). Samples are evaluated in batches (lab/fit/residual_blocks.cc
// ResidualBatch), and a loss on a batch would weigh its summed squares.
TEST(DepthFit, HuberLossWeighsEachSampleByItsOwnResidual) {
  std::vector<PairedSample> samples;
  for (int pose = 0; pose < 20; ++pose) {
    for (int k = 0; k < 40; ++k) {
      PairedSample s;
      s.frame = pose, s.pose = pose, s.board_point = k;
      s.depth_m = 0.6 + 0.12 * pose + 0.005 * k;
      const double outlier_mm = k % 9 == 4 ? 25.0 + pose : 0.0;
      s.raw = (s.depth_m + 0.0098) * 1020 + (k % 2 ? 1.0 : -1.0) * 0.8 + outlier_mm;
      samples.push_back(s);
    }
  }
  const double scale = 2;
  Eigen::Vector2d closed(1020, 10);  // mm = alpha z + beta
  for (int iteration = 0; iteration < 200; ++iteration) {
    Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
    Eigen::Vector2d right = Eigen::Vector2d::Zero();
    for (const auto& s : samples) {
      const double r = s.raw - closed[0] * s.depth_m - closed[1];
      const double w = std::abs(r) <= scale ? 1 : scale / std::abs(r);
      const Eigen::Vector2d row(s.depth_m, 1);
      normal += w * row * row.transpose(), right += w * row * s.raw;
    }
    closed = normal.ldlt().solve(right);
  }
  for (double huber : {0.0, scale}) {
    DepthFitOptions options;
    options.huber_raw = huber;
    const auto fit = RunDepthModelFit(options, {model::BaseForm::kLinearMm, {}}, samples);
    ASSERT_TRUE(Accepted(fit));
    const std::vector<double>& p = std::get<DepthFit>(fit).parameters;  // z = a mm + b
    const double alpha = 1 / p[0], beta = -p[1] / p[0];
    if (huber > 0) {
      EXPECT_NEAR(alpha, closed[0], 1e-6 * closed[0]);
      EXPECT_NEAR(beta, closed[1], 1e-3);
    } else {  // the outliers pull a least-squares fit away: the comparison above can fail
      EXPECT_GT(std::abs(beta - closed[1]), 1.0);
    }
  }
}

// Large models are solved sparse and take their covariance from the normal
// equations (lab/fit/covariance.cc): on the same samples both paths must give
// the dense path's parameters and covariance. Two folds keep the jackknife
// out, so the covariance compared is the samples' own.
TEST(DepthFit, SparsePathMatchesTheDenseOne) {
  const auto samples = Synthetic(5, [](const PairedSample& s) { return 2 * std::sin(s.u / 90) * std::cos(s.v / 70); });
  const model::ModelDefinition field{model::BaseForm::kReciprocal, {Named("spatial_field")}};
  DepthFitOptions dense, sparse;
  dense.folds = sparse.folds = 2;
  dense.sparse_from_parameters = 1000;
  sparse.sparse_from_parameters = 1;
  const auto a = RunDepthModelFit(dense, field, samples), b = RunDepthModelFit(sparse, field, samples);
  ASSERT_TRUE(Accepted(a) && Accepted(b));
  const DepthFit &d = std::get<DepthFit>(a), &s = std::get<DepthFit>(b);
  ASSERT_EQ(d.parameters.size(), s.parameters.size());
  ASSERT_GT(d.parameters.size(), 30u);
  for (std::size_t i = 0; i < d.parameters.size(); ++i) {
    // The sparse path's trust region (dogleg) stops elsewhere within the
    // tolerances: far inside each parameter's own uncertainty (up to 2 % of
    // it measured, where the field's planes and its splines' own tilt are
    // told apart only by the splines' prior).
    EXPECT_NEAR(s.parameters[i], d.parameters[i], 0.05 * d.sigma[i]) << i;
    EXPECT_NEAR(s.sigma[i], d.sigma[i], 1e-3 * d.sigma[i]) << d.names[i].block << "." << d.names[i].name;
  }
  EXPECT_NEAR(s.covariance[0][1], d.covariance[0][1], 1e-3 * std::abs(d.covariance[0][1]));
  EXPECT_NEAR(s.held_out_raw.rms, d.held_out_raw.rms, 1e-4 * d.held_out_raw.rms);
}

// A model no effect of which gives its support has dense Jacobian rows:
// past a size, its covariance comes from the normal equations summed as
// matrix products (NormalEquationCovariance) instead of Ceres' SVD of the
// whole Jacobian; both must give the same sigmas.
TEST(DepthFit, NormalEquationCovarianceOfDenseRowsIsTheSvds) {
  const auto samples = Synthetic(8, [](const PairedSample& s) { return 0.8 * s.x - 0.5 * s.y * s.y; });
  const json spec = {
      {"name", "bowl"},
      {"formula", "p * x + q * y * y + r * x * y"},
      {"parameters",
       {{{"name", "p"}, {"unit", "raw"}}, {{"name", "q"}, {"unit", "raw"}}, {{"name", "r"}, {"unit", "raw"}}}}};
  const model::ModelDefinition bowl{model::BaseForm::kReciprocal, {model::EffectSpecFromJson(spec, "spec")}};
  DepthFitOptions svd, normal;
  svd.folds = normal.folds = 2;       // too few for the jackknife: the sigmas are the covariance's
  normal.sparse_from_parameters = 1;  // the normal equations for any model
  const auto a = RunDepthModelFit(svd, bowl, samples), b = RunDepthModelFit(normal, bowl, samples);
  ASSERT_TRUE(Accepted(a) && Accepted(b));
  const DepthFit &d = std::get<DepthFit>(a), &n = std::get<DepthFit>(b);
  for (std::size_t i = 0; i < d.parameters.size(); ++i)
    EXPECT_NEAR(n.sigma_samples[i], d.sigma_samples[i], 1e-6 * d.sigma_samples[i]) << d.names[i].name;
  EXPECT_NEAR(n.covariance[0][3], d.covariance[0][3], 1e-6 * std::abs(d.covariance[0][3]));
}

// A B-spline effect gives each sample's support (effect.h): its controls are
// then one block each and each sample holds the 17 it reaches, and the fit
// is the one-block fit's. Samples in the image's last span reach every
// control (the last is minus the sum of the others); with them the split fit
// is solved by conjugate gradients (lab/fit/solve.cc), and both stop
// within Ceres' tolerances of the same optimum but not at one point: with 4
// such samples the split fit ended at a 1e-5 lower cost, its parameters up to
// 0.43 sigma and its jackknife sigmas up to 47 % from the one-block fit's.
void ExpectSplitMatchesOneBlock(int corner_samples, double parameter_sigmas, double sigma_share,
                                double held_out_share) {
  SCOPED_TRACE(std::to_string(corner_samples) + " samples in the last span");
  auto samples = Synthetic(6, [](const PairedSample& s) { return 1.5 * std::sin(s.u / 40) * std::cos(s.v / 30); });
  for (int k = 0; k < corner_samples; ++k) samples[k].u = 620 + 2.0 * k, samples[k].v = 460 + 3.0 * k;
  const model::ModelDefinition pattern{model::BaseForm::kReciprocal, {Named("disparity_pattern")}};
  DepthFitOptions split, whole;
  split.folds = whole.folds = 3;
  split.max_iterations = whole.max_iterations = 200;
  whole.split_by_support = false;
  const auto a = RunDepthModelFit(whole, pattern, samples), b = RunDepthModelFit(split, pattern, samples);
  ASSERT_TRUE(Accepted(a) && Accepted(b));
  const DepthFit &w = std::get<DepthFit>(a), &s = std::get<DepthFit>(b);
  ASSERT_EQ(w.parameters.size(), s.parameters.size());
  ASSERT_GT(w.parameters.size(), 700u);
  EXPECT_TRUE(w.converged && s.converged);
  for (std::size_t i = 0; i < w.parameters.size(); ++i) {
    EXPECT_NEAR(s.parameters[i], w.parameters[i], parameter_sigmas * w.sigma[i]) << w.names[i].name;
    EXPECT_NEAR(s.sigma[i], w.sigma[i], sigma_share * w.sigma[i]) << w.names[i].name;
  }
  EXPECT_NEAR(s.held_out_raw.rms, w.held_out_raw.rms, held_out_share * w.held_out_raw.rms);
  EXPECT_LT(s.raw.rms, 0.5);  // the pattern was fitted (1.5 raw), not left at zero
}

TEST(DepthFit, SplitBlocksMatchOneBlockPerEffect) {
  ExpectSplitMatchesOneBlock(0, 0.01, 1e-3, 1e-4);
  ExpectSplitMatchesOneBlock(4, 0.5, 0.5, 1e-3);
}

// The diagnosis compares candidates by their held-out residuals alone
// (RunHeldOutFit): they must be the full fit's, sample for sample, with a
// warm start the full fit uses and the folds do not, and with an effect
// that reads the fit raw (radial_billow).
TEST(DepthFit, HeldOutAloneIsTheFullFitsHeldOut) {
  const auto samples = Synthetic(7, [](const PairedSample& s) { return 0.01 * (s.raw - 700); });
  const model::ModelDefinition drift{model::BaseForm::kReciprocal, {Named("thermal_drift"), Named("radial_billow")}};
  DepthFitOptions options;
  options.folds = 5;
  options.start = WarmStartFrom(Fit({model::BaseForm::kReciprocal, {}}, samples));
  const auto full = RunDepthModelFit(options, drift, samples);
  const auto alone = RunHeldOutFit(options, drift, samples);
  ASSERT_TRUE(Accepted(full) && Accepted(alone));
  const DepthFit& f = std::get<DepthFit>(full);
  const HeldOutFit& h = std::get<HeldOutFit>(alone);
  EXPECT_EQ(h.parameters, f.parameters.size());
  ASSERT_EQ(h.held_out_residual_raw.size(), f.held_out_residual_raw.size());
  for (std::size_t i = 0; i < samples.size(); ++i)
    ASSERT_EQ(h.held_out_residual_raw[i], f.held_out_residual_raw[i]) << i;
  EXPECT_EQ(h.held_out_raw.rms, f.held_out_raw.rms);
  // What the full fit rejects, so does the held-out fit, for the same reason.
  const std::vector<PairedSample> few(samples.begin(), samples.begin() + 10);
  const auto rejected = RunHeldOutFit(options, drift, few);
  ASSERT_FALSE(Accepted(rejected));
  EXPECT_EQ(std::get<Rejection>(rejected).reason, std::get<Rejection>(RunDepthModelFit(options, drift, few)).reason);
}

TEST(FormulaEffect, FitsLikeTheCompiledOne) {
  const auto samples = Synthetic(4, [](const PairedSample& s) { return s.raw > 700 ? 2.0 : 0.0; });
  const json spec = {
      {"name", "raw_step"},
      {"formula", "height * (raw > 700)"},
      {"parameters", {{{"name", "height"}, {"unit", "raw"}, {"initial", 0}, {"lower", -20}, {"upper", 20}}}}};
  const DepthFit plain = Fit({model::BaseForm::kReciprocal, {}}, samples);
  const DepthFit stepped = Fit({model::BaseForm::kReciprocal, {model::EffectSpecFromJson(spec, "spec")}}, samples);
  EXPECT_LT(stepped.held_out_raw.rms, 0.8 * plain.held_out_raw.rms);
  EXPECT_NEAR(stepped.parameters[2], 2.0, 0.3);
  // The diagnosis of the plain model points along the raw value (or depth).
  const Diagnosis d = RunModelDiagnosis({}, samples, plain);
  const std::string top = d.covariates.front().covariate;
  EXPECT_TRUE(top == "raw" || top == "depth") << top << ": " << Words(d);
}

std::string ErrorOf(const json& spec) {
  try {
    ModelSpecFromJson(json{{"schema_version", 2}, {"effects", {spec}}}, "model.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(FormulaEffect, BadFormulasGiveClearErrors) {
  const json k = {{{"name", "k"}}};
  EXPECT_NE(ErrorOf({{"name", "e"}, {"formula", "k * (raw - "}, {"parameters", k}}).find("invalid formula"),
            std::string::npos);
  const std::string unknown = ErrorOf({{"name", "e"}, {"formula", "k * temperature"}, {"parameters", k}});
  EXPECT_NE(unknown.find("unknown variable \"temperature\""), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("model.json.effects[0]"), std::string::npos) << unknown;
  EXPECT_NE(ErrorOf({{"name", "e"}, {"formula", "raw = 3"}, {"parameters", k}}).find("assigns"), std::string::npos);
  EXPECT_NE(ErrorOf({{"name", "e"}, {"formula", "system(\"ls\")"}, {"parameters", k}}).find("invalid formula"),
            std::string::npos);
  EXPECT_NE(ErrorOf({{"name", "e"}, {"formula", "k"}, {"parameters", {{{"name", "raw"}}}}}).find("covariate's name"),
            std::string::npos);
  EXPECT_NE(ErrorOf("no_such_effect").find("unknown effect \"no_such_effect\""), std::string::npos);
  // Division by zero is caught before the fit, naming a sample.
  const auto samples = Synthetic(5, [](const PairedSample&) { return 0.0; });
  const json divide = {
      {"name", "e"}, {"formula", "k / (raw - raw)"}, {"parameters", {{{"name", "k"}, {"initial", 1}}}}};
  const auto fit =
      RunDepthModelFit({}, {model::BaseForm::kReciprocal, {model::EffectSpecFromJson(divide, "m")}}, samples);
  ASSERT_FALSE(Accepted(fit));
  EXPECT_NE(std::get<Rejection>(fit).reason.find("division by zero"), std::string::npos);
}

}  // namespace
}  // namespace speckle
