#include "stages/board_plane.h"

#include "schemas/option_check.h"
#include "stages/depth_region.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <Eigen/Eigenvalues>

#include <tbb/parallel_for.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>

namespace speckle {
namespace {

// raw - the raw value the model predicts where pixel (u, v)'s ray meets the
// board plane, with intrinsics, extrinsics and depth model all free.
struct PlanePixelResidual {
  PlanePixelResidual(model::BaseForm form, const Eigen::Vector3d& pixel, const Eigen::Vector3d& normal_c,
                     double offset_c)
      : form(form), pixel(pixel), normal_c(normal_c), offset_c(offset_c) {}
  template <typename T>
  bool operator()(const T* k, const T* rotation, const T* translation, const T* depth, T* residual) const {
    const T n_c[3] = {T(normal_c.x()), T(normal_c.y()), T(normal_c.z())};
    T n_d[3];
    ceres::AngleAxisRotatePoint(rotation, n_c, n_d);
    const T offset_d = T(offset_c) + n_d[0] * translation[0] + n_d[1] * translation[1] + n_d[2] * translation[2];
    const T x = (T(pixel.x()) - k[2]) / k[0], y = (T(pixel.y()) - k[3]) / k[1];
    const T z = offset_d / (n_d[0] * x + n_d[1] * y + n_d[2]);
    residual[0] = T(pixel.z()) - model::RawFromDepth(form, depth, z);
    return true;
  }
  model::BaseForm form;
  Eigen::Vector3d pixel, normal_c;
  double offset_c;
};

template <int N>
ceres::CostFunction* MakePlaneCost(model::BaseForm form, const Eigen::Vector3d& pixel, const Eigen::Vector3d& n,
                                   double d) {
  return new ceres::AutoDiffCostFunction<PlanePixelResidual, 1, 4, 3, 3, N>(new PlanePixelResidual(form, pixel, n, d));
}

}  // namespace

StageResult<BoardRegion> RunBoardRegion(const BoardRegionOptions& options, const cv::Mat& raw,
                                        const DepthReading& reading, const std::array<Eigen::Vector2d, 4>& outline,
                                        double square_px) {
  if (raw.empty()) return Rejection{"board_region", kNoDepthImage};
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const auto& c : outline) centre += c / 4;
  const cv::Mat gate = GatePolygon(raw.size(), outline, options.margin_squares * square_px);
  // Seed: the valid pixel nearest the chessboard's centre.
  cv::Point seed(-1, -1);
  double best = 1e18;
  for (int v = 0; v < raw.rows; ++v)
    for (int u = 0; u < raw.cols; ++u)
      if (gate.at<std::uint8_t>(v, u) && reading.IsReading(raw.at<std::uint16_t>(v, u))) {
        const double d = std::hypot(u - centre.x(), v - centre.y());
        if (d < best) best = d, seed = {u, v};
      }
  if (seed.x < 0 || best > square_px * 2)
    return Rejection{"board_region", "no depth reading where the board should be"};
  cv::Mat board = GrowRegion(raw, gate, seed, options.max_step_raw, reading);
  cv::erode(board, board, cv::Mat(), cv::Point(-1, -1), options.erode_px);
  BoardRegion region;
  for (int v = 0; v < raw.rows; v += options.stride)
    for (int u = 0; u < raw.cols; u += options.stride)
      if (board.at<std::uint8_t>(v, u)) region.pixels.emplace_back(u, v, raw.at<std::uint16_t>(v, u));
  if (static_cast<int>(region.pixels.size()) < options.min_pixels) {
    return Rejection{"board_region", "the board region has only " + std::to_string(region.pixels.size()) + " pixels"};
  }
  return region;
}

StageResult<JointPlaneResult> RunJointPlaneCalibration(const JointPlaneOptions& options,
                                                       const std::vector<PlaneObservation>& observations,
                                                       const CameraIntrinsics& initial_depth,
                                                       const Eigen::Isometry3d& initial_depth_from_colour) {
  if (observations.size() < 4) {
    return Rejection{"joint_plane_calibration",
                     "needs board planes from at least 4 poses, found " + std::to_string(observations.size())};
  }
  double k[4] = {initial_depth.camera_matrix(0, 0), initial_depth.camera_matrix(1, 1),
                 initial_depth.camera_matrix(0, 2), initial_depth.camera_matrix(1, 2)};
  const Eigen::AngleAxisd aa(initial_depth_from_colour.linear());
  double rotation[3], translation[3];
  Eigen::Vector3d::Map(rotation) = aa.angle() * aa.axis();
  Eigen::Vector3d::Map(translation) = initial_depth_from_colour.translation();
  std::vector<double> depth = model::Info(options.form).initial;
  const int n = static_cast<int>(depth.size());
  ceres::Problem problem;
  int pixels = 0;
  for (const auto& o : observations) {
    const Eigen::Vector3d normal = o.colour_from_board.linear().col(2);
    const double offset = normal.dot(o.colour_from_board.translation());
    for (const auto& p : o.region.pixels) {
      auto* cost = n == 2 ? MakePlaneCost<2>(options.form, p, normal, offset)
                          : MakePlaneCost<3>(options.form, p, normal, offset);
      problem.AddResidualBlock(cost, new ceres::HuberLoss(options.huber_raw), k, rotation, translation, depth.data());
      ++pixels;
    }
  }
  ceres::Solver::Options solver;
  solver.max_num_iterations = options.max_iterations;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.num_threads = 2;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  if (!summary.IsSolutionUsable())
    return Rejection{"joint_plane_calibration", "Ceres found no solution: " + summary.BriefReport()};
  JointPlaneResult out;
  out.depth = initial_depth;
  out.depth.stddev = {};
  out.depth.camera_matrix = cv::Matx33d(k[0], 0, k[2], 0, k[1], k[3], 0, 0, 1);
  out.depth.distortion = {};
  const Eigen::Vector3d rv = Eigen::Vector3d::Map(rotation);
  out.depth_from_colour.linear() =
      rv.norm() > 0 ? Eigen::AngleAxisd(rv.norm(), rv.normalized()).toRotationMatrix() : Eigen::Matrix3d::Identity();
  out.depth_from_colour.translation() = Eigen::Vector3d::Map(translation);
  out.depth_parameters = depth;
  out.pixels = pixels;
  out.rms_raw = std::sqrt(2 * summary.final_cost / std::max(1, pixels));
  out.solver_report = summary.BriefReport();
  return out;
}

void AddJointPlaneUncertainty(const JointPlaneOptions& options, const std::vector<PlaneObservation>& observations,
                              JointPlaneResult& result) {
  std::vector<int> poses;
  for (const auto& o : observations)
    if (poses.empty() || poses.back() != o.pose) poses.push_back(o.pose);
  const int groups = std::min<int>(options.jackknife_groups, static_cast<int>(poses.size()) / 4);
  if (groups < 3) return;
  std::vector<std::optional<JointPlaneResult>> refits(static_cast<std::size_t>(groups));
  tbb::parallel_for(0, groups, [&](int g) {
    std::vector<PlaneObservation> others;  // whole poses leave together
    for (const auto& o : observations) {
      const auto at = std::find(poses.begin(), poses.end(), o.pose) - poses.begin();
      if (static_cast<int>(at * groups / static_cast<std::ptrdiff_t>(poses.size())) != g) others.push_back(o);
    }
    auto refit = RunJointPlaneCalibration(options, others, result.depth, result.depth_from_colour);
    if (Accepted(refit)) refits[static_cast<std::size_t>(g)] = std::move(std::get<JointPlaneResult>(refit));
  });
  std::vector<const JointPlaneResult*> kept;
  for (const auto& r : refits)
    if (r) kept.push_back(&*r);
  if (kept.size() < 3) return;
  for (const auto* r : kept) result.jackknife_refits.emplace_back(r->depth, r->depth_from_colour);
  const double n = static_cast<double>(kept.size());
  const auto spread = [&](const auto& value) {  // the jackknife's standard deviation
    double mean = 0, squares = 0;
    for (const auto* r : kept) mean += value(*r) / n;
    for (const auto* r : kept) squares += std::pow(value(*r) - mean, 2);
    return std::sqrt((n - 1) / n * squares);
  };
  const std::array<std::pair<int, int>, 4> at = {{{0, 0}, {1, 1}, {0, 2}, {1, 2}}};  // fx, fy, cx, cy
  for (std::size_t i = 0; i < at.size(); ++i)
    result.depth.stddev[i] =
        spread([&](const JointPlaneResult& r) { return r.depth.camera_matrix(at[i].first, at[i].second); });
  // The translation's sigma sets how well every depth's offset is known.
  for (int i = 0; i < 3; ++i)
    result.translation_sigma_m[i] =
        spread([&](const JointPlaneResult& r) { return r.depth_from_colour.translation()[i]; });
}

std::vector<std::vector<double>> JointPlanePerturbations(const std::vector<PlaneObservation>& observations,
                                                         const JointPlaneResult& result) {
  const auto& refits = result.jackknife_refits;
  if (refits.empty()) return {};
  const Eigen::Index n = static_cast<Eigen::Index>(refits.size());
  std::vector<std::vector<double>> depths;  // [refit][sample]
  for (const auto& [depth, depth_from_colour] : refits) {
    std::vector<double>& z = depths.emplace_back();
    for (const auto& s : PlaneSamples(observations, depth, depth_from_colour)) z.push_back(s.depth_m);
  }
  const Eigen::Index samples = static_cast<Eigen::Index>(depths[0].size());
  // Jackknife deviations, scaled so that their outer products sum to its covariance.
  Eigen::MatrixXd d(n, samples);
  for (Eigen::Index r = 0; r < n; ++r) d.row(r) = Eigen::Map<const Eigen::RowVectorXd>(depths[r].data(), samples);
  d.rowwise() -= d.colwise().mean();
  d *= std::sqrt((n - 1.0) / n);
  // Principal directions from the n x n Gram matrix (n refits, many samples).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> gram(d * d.transpose());
  const double total = gram.eigenvalues().sum();
  std::vector<double> reference;
  for (const auto& s : PlaneSamples(observations, result.depth, result.depth_from_colour))
    reference.push_back(s.depth_m);
  std::vector<std::vector<double>> out;
  for (Eigen::Index k = n - 1; k >= 0 && total > 0; --k) {
    const double variance = gram.eigenvalues()[k];
    if (variance < 0.01 * total) break;
    // The deviation along eigenvector a: d^T a, one sigma (|d^T a| = sqrt(variance)).
    const Eigen::VectorXd along = d.transpose() * gram.eigenvectors().col(k);
    std::vector<double>& moved = out.emplace_back(reference);
    for (Eigen::Index i = 0; i < samples; ++i) moved[static_cast<std::size_t>(i)] += along[i];
  }
  return out;
}

std::vector<PairedSample> PlaneSamples(const std::vector<PlaneObservation>& observations, const CameraIntrinsics& depth,
                                       const Eigen::Isometry3d& depth_from_colour) {
  std::vector<PairedSample> samples;
  const Eigen::Isometry3d colour_from_depth = depth_from_colour.inverse();
  for (const auto& o : observations) {
    const Eigen::Isometry3d depth_from_board = depth_from_colour * o.colour_from_board;
    const Eigen::Vector3d n = depth_from_board.linear().col(2);
    const double d = n.dot(depth_from_board.translation());
    const double tilt = std::acos(std::min(1.0, std::abs(n.z()))) * 180 / M_PI;
    for (const auto& p : o.region.pixels) {
      const Eigen::Vector2d xy = depth.Undistort(p.head<2>());
      const Eigen::Vector3d ray(xy.x(), xy.y(), 1);
      const double z = d / n.dot(ray);
      PairedSample s;
      s.frame = o.frame;
      s.pose = o.pose;
      s.time_s = o.time_s;
      s.u = p.x(), s.v = p.y(), s.x = xy.x(), s.y = xy.y();
      s.raw = p.z();
      s.depth_m = z;
      s.in_colour = colour_from_depth * (z * ray);
      s.tilt_deg = tilt;
      s.albedo = 0.5;
      s.point = SamplePoint::kBoardPlanePixel;
      samples.push_back(s);
    }
  }
  return samples;
}

bool BoardRegionOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .AtLeast(margin_squares, 0, "margin_squares")
      .Positive(max_step_raw, "max_step_raw")
      .AtLeast(erode_px, 0, "erode_px")
      .AtLeast(stride, 1, "stride")
      .AtLeast(min_pixels, 1, "min_pixels")
      .valid();
}

bool JointPlaneOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .AtLeast(huber_raw, 0, "huber_raw")
      .AtLeast(max_iterations, 1, "max_iterations")
      .AtLeast(jackknife_groups, 2, "jackknife_groups")
      .valid();
}

}  // namespace speckle
