#include "stages/outline_calibration.h"

#include <ceres/ceres.h>
#include <ceres/normal_prior.h>
#include <ceres/rotation.h>

#include <tbb/parallel_for.h>
#include <algorithm>

#include "model/base_form.h"
#include "schemas/option_check.h"
#include "stages/ceres_blocks.h"
#include "stages/lens_autodiff.h"
#include "stages/scaled_covariance.h"

namespace speckle {
namespace {

// Residual: an outline corner seen from the colour pose, moved into the depth
// camera by the extrinsics, projected through the depth camera, minus its
// quad corner. The depth image was exposed `delay` seconds after the colour
// image, while the corner moved at `velocity` (colour-camera metres per
// second). With the depth camera free, all five Brown-Conrady terms are
// fitted: the board-plane pixels cover the image where four corners a view
// cannot.

struct OutlineReprojection {
  OutlineReprojection(const Eigen::Vector3d& in_colour, const Eigen::Vector2d& observed, const Eigen::Vector2d& outward,
                      const Eigen::Vector3d& velocity, double sigma_px)
      : in_colour(in_colour), observed(observed), outward(outward), velocity(velocity), sigma_px(sigma_px) {}
  template <typename T>
  bool operator()(const T* rotation, const T* translation, const T* delay, const T* k, const T* lens,
                  const T* edge_offset, T* residual) const {
    const T p[3] = {in_colour.x() + delay[0] * velocity.x(), in_colour.y() + delay[0] * velocity.y(),
                    in_colour.z() + delay[0] * velocity.z()};
    T q[3];
    ceres::AngleAxisRotatePoint(rotation, p, q);
    for (int i = 0; i < 3; ++i) q[i] += translation[i];
    T pixel[2];
    Project(k, lens, q, pixel);
    residual[0] = (pixel[0] + edge_offset[0] * T(outward.x()) - T(observed.x())) / T(sigma_px);
    residual[1] = (pixel[1] + edge_offset[0] * T(outward.y()) - T(observed.y())) / T(sigma_px);
    return true;
  }
  Eigen::Vector3d in_colour;
  Eigen::Vector2d observed, outward;
  Eigen::Vector3d velocity;
  double sigma_px;
};

// Residual: a board pixel's raw value minus the raw value the base form
// gives for the depth where its ray meets the board's plane (known in the
// colour camera), in units of the raw noise. The pixel is undistorted
// through the lens (stages/lens_autodiff.h), its derivatives with it.
//
// The raw value is billowed as a wide-angle adapter billows it (thesis Eq.
// 4.2, model/effects/radial_billow.h: r^2 + bx x^2 + by y^2), bx and by
// nuisance parameters here. Without them the lens terms took the billowing
// up: its tens of raw units at the image's edge read as lens distortion, and
// a wide-angle room session's depth camera came out with k1 -0.06 +- 0.86
// (true -0.23), fx 373 +- 7 (true 379), 45 of 75 board frames unpaired; the same
// seed drawn without billowing gave k1 -0.234 +- 0.004. Both are bounded
// below by zero: billowing only adds.
struct PlaneRaw {
  PlaneRaw(const Eigen::Vector3d& pixel, const Eigen::Vector3d& normal_c, double offset_c, double sigma,
           model::BaseForm form = model::BaseForm::kReciprocal)
      : pixel(pixel), normal_c(normal_c), offset_c(offset_c), sigma(sigma), form(form) {}
  template <typename T>
  bool operator()(const T* rotation, const T* translation, const T* k, const T* lens, const T* base, const T* billow,
                  T* residual) const {
    const T n_c[3] = {T(normal_c.x()), T(normal_c.y()), T(normal_c.z())};
    T n[3];
    ceres::AngleAxisRotatePoint(rotation, n_c, n);
    const T offset = T(offset_c) + n[0] * translation[0] + n[1] * translation[1] + n[2] * translation[2];
    T xy[2];
    Undistort(k, lens, pixel.x(), pixel.y(), xy);
    const T x = xy[0], y = xy[1];
    const T z = offset / (n[0] * x + n[1] * y + n[2]);
    // sqrt(raw^2 + b) written as raw plus its excess, which keeps the sign of
    // a raw value the fit's early steps may drive below zero.
    const T raw = model::RawFromDepth(form, base, z), b = billow[0] * x * x + billow[1] * y * y;
    residual[0] = (T(pixel.z()) - raw - b / (sqrt(raw * raw + b) + abs(raw))) / T(sigma);
    return true;
  }
  Eigen::Vector3d pixel, normal_c;
  double offset_c, sigma;
  model::BaseForm form;
};

model::BaseForm PlaneForm(const DepthReading& reading) {
  return reading.units() == DepthUnits::kMillimetre ? model::BaseForm::kLinearMm : model::BaseForm::kReciprocal;
}

// The parameter blocks of one outline fit.
struct OutlineParameters {
  double rotation[3], translation[3], delay = 0, k[4], lens[5];
  // How far the depth step of the board's edge lies outside the true edge
  // (px): a structured-light sensor's edges are displaced by its matching
  // window, and a focal length would otherwise absorb it as a scale.
  double edge_offset_px = 0;
  std::vector<double> base = model::Info(model::BaseForm::kReciprocal).initial;  // the board planes' depth model
  double billow[2] = {0, 0};  // bx, by (raw^2) of the board planes' raw values (see PlaneRaw)

  OutlineParameters(const CameraIntrinsics& depth, const Eigen::Isometry3d& initial) {
    const Eigen::AngleAxisd angle_axis(initial.linear());
    Eigen::Vector3d::Map(rotation) = angle_axis.angle() * angle_axis.axis();
    Eigen::Vector3d::Map(translation) = initial.translation();
    const cv::Matx33d& m = depth.camera_matrix;
    k[0] = m(0, 0), k[1] = m(1, 1), k[2] = m(0, 2), k[3] = m(1, 2);
    std::copy(depth.distortion.begin(), depth.distortion.end(), lens);
  }
  Eigen::Isometry3d DepthFromColour() const {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d rv = Eigen::Vector3d::Map(rotation);
    if (rv.norm() > 0) t.linear() = Eigen::AngleAxisd(rv.norm(), rv.normalized()).toRotationMatrix();
    t.translation() = Eigen::Vector3d::Map(translation);
    return t;
  }
  CameraIntrinsics Camera(const CameraIntrinsics& prior) const {
    CameraIntrinsics c = prior;
    c.camera_matrix = cv::Matx33d(k[0], 0, k[2], 0, k[1], k[3], 0, 0, 1);
    std::copy(lens, lens + 5, c.distortion.begin());
    return c;
  }
};

// A board that moves gives the colour-to-depth delay: fitted only when the
// views' typical speed makes it observable.
bool DelayObservable(const ExtrinsicsOptions& options, const std::vector<ExtrinsicsView>& views) {
  std::vector<double> speeds;
  for (const auto& v : views) speeds.push_back(v.board_velocity.norm());
  if (speeds.empty()) return false;
  std::nth_element(speeds.begin(), speeds.begin() + static_cast<std::ptrdiff_t>(speeds.size() / 2), speeds.end());
  return speeds[speeds.size() / 2] >= options.min_speed_for_delay_m_s;
}

// RMS distance (px) of a view's four outline corners from where the fit puts them.
double ViewError(const ExtrinsicsView& v, const std::array<Eigen::Vector3d, 4>& outline, const CameraIntrinsics& depth,
                 const Eigen::Isometry3d& depth_from_colour, double delay, double edge_offset_px) {
  double sum = 0;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d at_depth_exposure = v.colour_from_board * outline[k] + delay * v.board_velocity;
    const Eigen::Vector2d predicted =
        depth.Project(depth_from_colour * at_depth_exposure) + edge_offset_px * CornerOutward(v.quad, k);
    sum += (predicted - v.quad.corners_px[k]).squaredNorm();
  }
  return std::sqrt(sum / 4);
}

// The board-plane term of the depth camera's fit (see ExtrinsicsView).
void AddBoardPlanes(const ExtrinsicsOptions& options, const DepthReading& reading,
                    const std::vector<ExtrinsicsView>& views, const std::vector<bool>& used, OutlineParameters& p,
                    ceres::Problem& problem) {
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (!used[i]) continue;
    const Eigen::Vector3d normal = views[i].colour_from_board.linear().col(2);
    const double offset = normal.dot(views[i].colour_from_board.translation());
    for (const auto& pixel : views[i].board_pixels) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<PlaneRaw, 1, 3, 3, 4, 5, 2, 2>(new PlaneRaw(
              pixel, normal, offset, options.plane_raw_sigma * reading.UnitsPerRawStep(pixel.z()), PlaneForm(reading))),
          new ceres::HuberLoss(options.plane_huber), p.rotation, p.translation, p.k, p.lens, p.base.data(), p.billow);
    }
  }
  if (!problem.HasParameterBlock(p.billow)) return;
  // Billowing is a disparity effect: a sensor that reports millimetres has
  // none to fit (and its readings' squares are not raw^2).
  if (reading.units() == DepthUnits::kMillimetre) {
    HoldConstant(problem, p.billow);
    return;
  }
  for (int i = 0; i < 2; ++i) BoundParameter(problem, p.billow, i, 0, 1e7);
}

// The IR chessboard's intrinsics as Gaussian priors on the depth camera's
// blocks (residuals in units of their sigma, as the corners' and the board
// planes' are); a term with no sigma is held at its value by a tight one.
void AddIntrinsicsPrior(const CameraIntrinsics& prior, OutlineParameters& p, ceres::Problem& problem) {
  const OutlineParameters at(prior, Eigen::Isometry3d::Identity());
  constexpr double kHeld = 1e-9;
  const auto block = [&](const double* values, int size, int first_sigma, double* parameters) {
    ceres::Matrix a = ceres::Matrix::Zero(size, size);
    ceres::Vector b(size);
    for (int i = 0; i < size; ++i) {
      const double sigma = prior.stddev[static_cast<std::size_t>(first_sigma + i)];
      a(i, i) = 1 / (sigma > 0 ? sigma : kHeld * std::max(1.0, std::abs(values[i])));
      b(i) = values[i];
    }
    problem.AddResidualBlock(new ceres::NormalPrior(a, b), nullptr, parameters);
  };
  block(at.k, 4, 0, p.k);
  block(at.lens, 5, 4, p.lens);
}

int CountUsed(const std::vector<bool>& used) { return static_cast<int>(std::count(used.begin(), used.end(), true)); }

// Standard deviations of the free blocks from the fit's covariance, scaled by
// its residual variance. False when the covariance is rank-deficient: the
// views do not pin those parameters down.
bool Uncertainty(ceres::Problem& problem, OutlineParameters& p, bool free_camera, double variance,
                 ExtrinsicsResult& result) {
  const auto covariance = ScaledCovariance(problem);
  if (!covariance) return false;
  const auto sigma = [&](const double* block, int i) {
    return std::sqrt(std::max(0.0, covariance->Variance(block, i) * variance));
  };
  for (int i = 0; i < 3; ++i) result.translation_sigma_m[i] = sigma(p.translation, i);
  if (!free_camera) return true;
  auto& stddev = result.depth->stddev;  // fx, fy, cx, cy, k1, k2, p1, p2, k3
  stddev = {};
  for (int i = 0; i < 4; ++i) stddev[static_cast<std::size_t>(i)] = sigma(p.k, i);
  for (int i = 0; i < 5; ++i) stddev[static_cast<std::size_t>(4 + i)] = sigma(p.lens, i);
  result.depth->covariance = CameraCovariance(covariance->matrix, covariance->offset, p.k, p.lens, variance);
  return true;
}

// The outline fit, with the depth camera free or held. Views whose outline
// disagrees (a mis-extracted quad) are dropped and the fit repeated.
// How one outline fit runs.
struct FitMode {
  bool free_camera = false;
  int rounds = 2;           // fits, each after dropping the views that disagreed with the last
  bool uncertainty = true;  // the covariance (a jackknife refit needs none)
};

StageResult<ExtrinsicsResult> FitOutlines(const ExtrinsicsOptions& options, const DepthReading& reading,
                                          const BoardGeometry& board, const CameraIntrinsics& depth,
                                          const std::vector<ExtrinsicsView>& views, const Eigen::Isometry3d& initial,
                                          const FitMode& mode) {
  const bool free_camera = mode.free_camera;
  const auto outline = OutlineCorners(board);
  OutlineParameters p(depth, initial);
  p.base = model::Info(PlaneForm(reading)).initial;
  const bool fit_delay = DelayObservable(options, views);
  ExtrinsicsResult result;
  result.used.assign(views.size(), true);
  ceres::Problem problem;
  const int rounds = mode.rounds;
  // The extrinsics alone: residuals in pixels, Huber beyond 1 px. With the
  // depth camera free, corners and board pixels share one problem, each in
  // units of its own noise.
  const double corner_sigma = free_camera ? options.outline_corner_sigma_px : 1.0;
  const double corner_huber = free_camera ? 3.0 : 1.0;
  double final_cost = 0;
  int final_residuals = 0;
  for (int round = 0; round < rounds && CountUsed(result.used) >= 3; ++round) {
    problem = ceres::Problem();
    for (std::size_t i = 0; i < views.size(); ++i) {
      if (!result.used[i]) continue;
      for (int k = 0; k < 4; ++k) {
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<OutlineReprojection, 2, 3, 3, 1, 4, 5, 1>(
                new OutlineReprojection(views[i].colour_from_board * outline[k], views[i].quad.corners_px[k],
                                        CornerOutward(views[i].quad, k), views[i].board_velocity, corner_sigma)),
            new ceres::HuberLoss(corner_huber), p.rotation, p.translation, &p.delay, p.k, p.lens, &p.edge_offset_px);
      }
    }
    // Refining an IR chessboard's camera, the outline corners alone: the
    // board planes' raw values would let its lens terms take up depth errors
    // the diagnosis is there to find (a disparity pattern read as distortion
    // left the walls' undistortion grid making the boards worse).
    if (free_camera && !options.depth_prior) AddBoardPlanes(options, reading, views, result.used, p, problem);
    if (free_camera && options.depth_prior) AddIntrinsicsPrior(*options.depth_prior, p, problem);
    if (!fit_delay) HoldConstant(problem, &p.delay);
    if (!free_camera) {
      HoldConstant(problem, p.k);
      HoldConstant(problem, p.lens);
    }
    ceres::Solver::Options solver;
    solver.max_num_iterations = free_camera ? 100 : 50;
    // The billow's bounds make Ceres search along each step; a quadratic
    // needs only the cost at its trial point, the default cubic the Jacobian too.
    solver.line_search_interpolation_type = ceres::QUADRATIC;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
    if (!summary.IsSolutionUsable())
      return Rejection{"outline_calibration", "Ceres found no solution: " + summary.BriefReport()};
    final_cost = summary.final_cost, final_residuals = summary.num_residuals;
    const CameraIntrinsics camera = p.Camera(depth);
    const std::vector<bool> fitted = result.used;
    for (std::size_t i = 0; i < views.size(); ++i)
      result.used[i] =
          ViewError(views[i], outline, camera, p.DepthFromColour(), p.delay, p.edge_offset_px) < options.outlier_px;
    if (result.used == fitted) break;  // the next round would fit the same views from this minimum
  }
  const CameraIntrinsics camera = p.Camera(depth);
  result.depth_from_colour = p.DepthFromColour();
  if (fit_delay) result.delay_s = p.delay;
  double sum = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (!result.used[i]) continue;
    sum += std::pow(ViewError(views[i], outline, camera, result.depth_from_colour, p.delay, p.edge_offset_px), 2);
    ++result.views;
  }
  result.rms_px = result.views ? std::sqrt(sum / result.views) : 0;
  result.edge_offset_px = p.edge_offset_px;
  if (free_camera) result.depth = camera;
  const int parameters = 7 + (fit_delay ? 1 : 0) + (free_camera ? 11 : 0);  // edge offset always free
  const int dof = free_camera ? final_residuals - parameters : 1;
  if (mode.uncertainty && result.views >= 3 && dof > 0) {
    // Held camera: sum holds each view's mean over 4 corners of the squared
    // 2-D error. Free: residuals are in units of their noise; scale by what
    // the fit left.
    const double variance = free_camera ? 2 * final_cost / dof : sum / (2 * result.views);
    if (!Uncertainty(problem, p, free_camera, variance, result) && free_camera) {
      return Rejection{"outline_calibration",
                       "the outlines of " + std::to_string(result.views) +
                           " views do not pin the depth camera down (its covariance is singular)"};
    }
  }
  return result;
}

}  // namespace

std::optional<ExtrinsicsResult> RefitDepthCamera(const ExtrinsicsOptions& options, const DepthReading& reading,
                                                 const BoardGeometry& board, const std::vector<ExtrinsicsView>& views,
                                                 const ExtrinsicsResult& from) {
  if (!from.depth) return std::nullopt;
  auto refit = FitOutlines(options, reading, board, *from.depth, views, from.depth_from_colour, {true, 1, false});
  if (!Accepted(refit)) return std::nullopt;
  return std::get<ExtrinsicsResult>(std::move(refit));
}

double FittedValue(const ExtrinsicsResult& r, int i) {
  const CameraIntrinsics& c = *r.depth;
  if (i < 4)
    return std::array{c.camera_matrix(0, 0), c.camera_matrix(1, 1), c.camera_matrix(0, 2), c.camera_matrix(1, 2)}[i];
  if (i < 9) return c.distortion[static_cast<std::size_t>(i - 4)];
  return r.depth_from_colour.translation()[i - 9];
}

double& FittedSigma(ExtrinsicsResult& r, int i) {
  return i < 9 ? r.depth->stddev[static_cast<std::size_t>(i)] : r.translation_sigma_m[i - 9];
}

void AddJackknifeUncertainty(const ExtrinsicsOptions& options, const DepthReading& reading, const BoardGeometry& board,
                             const std::vector<ExtrinsicsView>& views, ExtrinsicsResult& result) {
  if (!result.depth || result.used.size() != views.size()) return;
  std::vector<ExtrinsicsView> kept;
  for (std::size_t i = 0; i < views.size(); ++i)
    if (result.used[i]) kept.push_back(views[i]);
  const int groups = std::min<int>(options.jackknife_groups, static_cast<int>(kept.size()) / 2);
  if (groups < 3) return;
  std::vector<std::optional<ExtrinsicsResult>> refits(static_cast<std::size_t>(groups));
  tbb::parallel_for(0, groups, [&](int g) {
    std::vector<ExtrinsicsView> others;  // consecutive views, so a still pose's frames mostly leave together
    for (std::size_t i = 0; i < kept.size(); ++i)
      if (static_cast<int>(i * static_cast<std::size_t>(groups) / kept.size()) != g) others.push_back(kept[i]);
    refits[static_cast<std::size_t>(g)] = RefitDepthCamera(options, reading, board, others, result);
  });
  int n = 0;
  for (const auto& r : refits) n += r.has_value();
  if (n < 3) return;
  for (int i = 0; i < kFittedValues; ++i) {
    double mean = 0, squares = 0;
    for (const auto& r : refits)
      if (r) mean += FittedValue(*r, i) / n;
    for (const auto& r : refits)
      if (r) squares += std::pow(FittedValue(*r, i) - mean, 2);
    double& sigma = FittedSigma(result, i);
    sigma = std::max(sigma, std::sqrt((n - 1.0) / n * squares));
  }
}

std::array<Eigen::Vector3d, 4> OutlineCorners(const BoardGeometry& board) {
  return {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(board.Width(), 0, 0),
          Eigen::Vector3d(board.Width(), board.Height(), 0), Eigen::Vector3d(0, board.Height(), 0)};
}

ExtrinsicsResult RunExtrinsicsCalibration(const ExtrinsicsOptions& options, const DepthReading& reading,
                                          const BoardGeometry& board, const CameraIntrinsics& depth,
                                          const std::vector<ExtrinsicsView>& views, const Eigen::Isometry3d& initial) {
  auto fitted = FitOutlines(options, reading, board, depth, views, initial, {false, 2, true});
  if (Accepted(fitted)) return std::get<ExtrinsicsResult>(std::move(fitted));
  ExtrinsicsResult unchanged;  // Ceres failed: keep the initial transform, used by no view
  unchanged.depth_from_colour = initial;
  return unchanged;
}

StageResult<ExtrinsicsResult> RunDepthCameraFromOutlines(const ExtrinsicsOptions& options, const DepthReading& reading,
                                                         const BoardGeometry& board, const CameraIntrinsics& prior,
                                                         const std::vector<ExtrinsicsView>& views,
                                                         const Eigen::Isometry3d& initial) {
  if (static_cast<int>(views.size()) < options.min_views_for_intrinsics) {
    return Rejection{"outline_calibration", "the depth camera needs depthboard outlines of at least " +
                                                std::to_string(options.min_views_for_intrinsics) + " views, found " +
                                                std::to_string(views.size())};
  }
  // From a nominal camera the first fit is coarse: two more after dropping outliers.
  auto fitted = FitOutlines(options, reading, board, prior, views, initial, {true, 3, true});
  if (!Accepted(fitted)) return fitted;
  auto& r = std::get<ExtrinsicsResult>(fitted);
  if (r.views < options.min_views_for_intrinsics) {
    return Rejection{"outline_calibration", "only " + std::to_string(r.views) + " of " + std::to_string(views.size()) +
                                                " outlines agree with one depth camera"};
  }
  return fitted;
}

double OutlineErrorPx(const BoardGeometry& board, const CameraIntrinsics& depth, const ExtrinsicsResult& fit,
                      const ExtrinsicsView& view) {
  return ViewError(view, OutlineCorners(board), depth, fit.depth_from_colour, fit.delay_s.value_or(0),
                   fit.edge_offset_px);
}

bool ExtrinsicsOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .Positive(outlier_px, "outlier_px")
      .AtLeast(min_speed_for_delay_m_s, 0, "min_speed_for_delay_m_s")
      .AtLeast(min_views_for_intrinsics, 4, "min_views_for_intrinsics")
      .Positive(plane_raw_sigma, "plane_raw_sigma")
      .Positive(outline_corner_sigma_px, "outline_corner_sigma_px")
      .AtLeast(jackknife_groups, 2, "jackknife_groups")
      .Positive(max_focal_sigma_share, "max_focal_sigma_share")
      .Positive(max_principal_point_sigma_px, "max_principal_point_sigma_px")
      .AtLeast(plane_huber, 0, "plane_huber")
      .valid();
}

// How a quad corner moves when both its sides move outwards by one pixel:
// (n1 + n2) / (1 + n1 . n2), n1 and n2 the sides' outward normals.
Eigen::Vector2d CornerOutward(const DepthboardQuad& quad, int corner) {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const auto& c : quad.corners_px) centre += c / 4;
  const auto normal = [&](int from, int to) {
    const Eigen::Vector2d along = (quad.corners_px[to] - quad.corners_px[from]).normalized();
    Eigen::Vector2d n(-along.y(), along.x());
    return (quad.corners_px[from] - centre).dot(n) > 0 ? n : Eigen::Vector2d(-n);
  };
  const Eigen::Vector2d n1 = normal((corner + 3) % 4, corner), n2 = normal(corner, (corner + 1) % 4);
  return (n1 + n2) / (1 + n1.dot(n2));
}

}  // namespace speckle
