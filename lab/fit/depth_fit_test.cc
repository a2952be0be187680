// The depth fit on synthetic samples drawn from a known model: base forms,
// effects recovered within their sigma, camera freedom, the sparse and dense
// paths, the covariance routes and the held-out fit.
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
#include "lab/fit/fit_samples.h"
#include "lab/fit/tangent_form_manifold.h"
#include "lab/lab_test_samples.h"
#include "lab/model_spec.h"
#include "model/depth_model.h"
#include "model/formula_effect.h"
#include "schemas/errors.h"

namespace speckle {
namespace {

using nlohmann::json;

int Iterations(const std::string& solver_report) {
  const auto at = solver_report.find("Iterations: ");
  return at == std::string::npos ? -1 : std::stoi(solver_report.substr(at + 12));
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
  DepthPerturbations perturbations{std::vector<std::vector<double>>(5)};
  for (auto& s : samples) {
    s.raw = (1 / s.depth_m - 4.51) / -0.00417 + noise(rng);
    for (int k = 0; k < 5; ++k)
      perturbations.depths[static_cast<std::size_t>(k)].push_back(s.depth_m *
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

// A model no effect of which gives its support has dense Jacobian rows,
// summed as matrix products (NormalEquationCovariance): its covariance is
// sigma^2 (J^T J)^-1, J the raw prediction's derivatives over the samples
// (here by central differences, independent of the fit's own gradients).
TEST(DepthFit, CovarianceOfDenseRowsIsTheInverseNormalEquations) {
  const auto samples = Synthetic(8, [](const PairedSample& s) { return 0.8 * s.x - 0.5 * s.y * s.y; });
  const json spec = {
      {"name", "bowl"},
      {"formula", "p * x + q * y * y + r * x * y"},
      {"parameters",
       {{{"name", "p"}, {"unit", "raw"}}, {{"name", "q"}, {"unit", "raw"}}, {{"name", "r"}, {"unit", "raw"}}}}};
  const model::ModelDefinition bowl{model::BaseForm::kReciprocal, {model::EffectSpecFromJson(spec, "spec")}};
  DepthFitOptions options;
  options.folds = 2;  // too few for the jackknife: the sigmas are the covariance's
  const auto result = RunDepthModelFit(options, bowl, samples);
  ASSERT_TRUE(Accepted(result));
  const DepthFit& fit = std::get<DepthFit>(result);
  const auto n = static_cast<Eigen::Index>(fit.parameters.size());
  Eigen::MatrixXd jacobian(static_cast<Eigen::Index>(samples.size()), n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double h = 1e-6 * std::max(std::abs(fit.parameters[j]), 1e-3);
    std::vector<double> plus = fit.parameters, minus = fit.parameters;
    plus[j] += h, minus[j] -= h;
    model::DepthModel up(bowl), down(bowl);
    up.SetFlat(plus), down.SetFlat(minus);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const model::Covariates c = FitCovariatesOf(samples[i]);
      jacobian(static_cast<Eigen::Index>(i), j) =
          (up.PredictRaw(samples[i].depth_m, c) - down.PredictRaw(samples[i].depth_m, c)) / (2 * h);
    }
  }
  double squares = 0;
  for (const double r : fit.residual_raw) squares += r * r;
  const Eigen::MatrixXd expected = squares / static_cast<double>(samples.size() - fit.parameters.size()) *
                                   (jacobian.transpose() * jacobian).inverse();
  for (Eigen::Index j = 0; j < n; ++j)
    EXPECT_NEAR(fit.sigma_samples[j], std::sqrt(expected(j, j)), 1e-4 * std::sqrt(expected(j, j))) << fit.names[j].name;
  EXPECT_NEAR(fit.covariance[0][3], expected(0, 3), 1e-4 * std::abs(expected(0, 3)));
}

// Parameters the samples cannot determine get no sigma, on both covariance
// routes: one that no sample's raw value depends on (a term that never
// applies: its sigma was 0, printed "held, not fitted") and two that move it
// alike (the pseudo-inverse split their sum, a finite sigma each). The
// well-posed ones keep theirs.
TEST(DepthFit, UnidentifiedParametersHaveNoSigma) {
  const auto samples = Synthetic(8, [](const PairedSample& s) { return 0.8 * s.x; });
  const json spec = {{"name", "odd"},
                     {"formula", "p * x + never * (raw > 5000) + q1 * y + q2 * y"},
                     {"parameters",
                      {json{{"name", "p"}, {"unit", "raw"}}, json{{"name", "never"}, {"unit", "raw"}},
                       json{{"name", "q1"}, {"unit", "raw"}}, json{{"name", "q2"}, {"unit", "raw"}}}}};
  const model::ModelDefinition odd{model::BaseForm::kReciprocal, {model::EffectSpecFromJson(spec, "spec")}};
  for (const std::size_t sparse_from : {std::size_t{1000}, std::size_t{1}}) {
    SCOPED_TRACE(sparse_from == 1 ? "normal equations" : "Ceres' SVD");
    DepthFitOptions options;
    options.sparse_from_parameters = sparse_from;
    const auto result = RunDepthModelFit(options, odd, samples);
    ASSERT_TRUE(Accepted(result));
    const DepthFit& fit = std::get<DepthFit>(result);
    std::set<std::string> unidentified;
    for (const std::size_t i : fit.unidentified) unidentified.insert(fit.names[i].name);
    EXPECT_EQ(unidentified, (std::set<std::string>{"never", "q1", "q2"}));
    for (std::size_t i = 0; i < fit.parameters.size(); ++i) {
      const bool named = unidentified.count(fit.names[i].name) > 0;
      EXPECT_EQ(std::isnan(fit.sigma[i]), named) << fit.names[i].name << " sigma " << fit.sigma[i];
      if (!named) EXPECT_GT(fit.sigma[i], 0) << fit.names[i].name;
    }
  }
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

}  // namespace
}  // namespace speckle
