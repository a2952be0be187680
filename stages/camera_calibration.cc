#include "stages/camera_calibration.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "schemas/brown_conrady.h"
#include "schemas/errors.h"
#include "stages/significant_digits.h"

namespace speckle {
namespace {

// Residual: an outline corner seen from the colour pose, moved into the depth
// camera by the unknown extrinsics, projected, minus its quad corner. The
// depth image was exposed `delay` seconds after the colour image, while the
// corner moved at `velocity` (colour-camera metres per second).
struct OutlineReprojection {
  OutlineReprojection(const Eigen::Vector3d& in_colour, const Eigen::Vector2d& observed, const Eigen::Vector3d& velocity,
                      const CameraIntrinsics& depth)
      : in_colour(in_colour), observed(observed), velocity(velocity), depth(depth) {}
  template <typename T>
  bool operator()(const T* rotation, const T* translation, const T* delay, T* residual) const {
    const T p[3] = {in_colour.x() + delay[0] * velocity.x(), in_colour.y() + delay[0] * velocity.y(),
                    in_colour.z() + delay[0] * velocity.z()};
    T q[3];
    ceres::AngleAxisRotatePoint(rotation, p, q);
    for (int i = 0; i < 3; ++i) q[i] += translation[i];
    T xd, yd;
    lens::Distort(q[0] / q[2], q[1] / q[2], depth.distortion, &xd, &yd);
    residual[0] = T(depth.camera_matrix(0, 0)) * xd + T(depth.camera_matrix(0, 2)) - T(observed.x());
    residual[1] = T(depth.camera_matrix(1, 1)) * yd + T(depth.camera_matrix(1, 2)) - T(observed.y());
    return true;
  }
  Eigen::Vector3d in_colour;
  Eigen::Vector2d observed;
  Eigen::Vector3d velocity;
  const CameraIntrinsics& depth;
};

}  // namespace

std::array<Eigen::Vector3d, 4> OutlineCorners(const BoardGeometry& board) {
  return {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(board.Width(), 0, 0),
          Eigen::Vector3d(board.Width(), board.Height(), 0), Eigen::Vector3d(0, board.Height(), 0)};
}

CameraIntrinsics RunIntrinsicsCalibration(const IntrinsicsOptions& options, const BoardGeometry& board,
                                          const std::vector<ChessboardDetection>& views) {
  if (static_cast<int>(views.size()) < options.min_views) {
    throw InputError("camera calibration needs at least " + std::to_string(options.min_views) +
                     " chessboard views, found " + std::to_string(views.size()));
  }
  const std::size_t step = std::max<std::size_t>(1, views.size() / static_cast<std::size_t>(options.max_views));
  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> image_points;
  for (std::size_t i = 0; i < views.size(); i += step) {
    object_points.push_back(board.InteriorCornerPoints());
    image_points.push_back(views[i].corners);
  }
  cv::Mat camera_matrix, distortion, stddev_intrinsics, stddev_extrinsics, per_view;
  std::vector<cv::Mat> rvecs, tvecs;
  const int flags = options.fix_k3 ? cv::CALIB_FIX_K3 : 0;
  CameraIntrinsics out;
  out.image_size = views.front().image_size;
  out.rms_reprojection_px =
      cv::calibrateCamera(object_points, image_points, out.image_size, camera_matrix, distortion, rvecs, tvecs,
                          stddev_intrinsics, stddev_extrinsics, per_view, flags);
  out.camera_matrix = cv::Matx33d(camera_matrix);
  for (int i = 0; i < 5; ++i) out.distortion[static_cast<std::size_t>(i)] = distortion.at<double>(i);
  // Four significant digits: the standard deviations come from an
  // ill-conditioned inverse whose last bits follow the memory layout (OpenCV
  // and BLAS kernels), so the same views gave values differing by 4e-6 from
  // run to run; the camera perturbations, parameter sigmas and noise floor
  // built on them would differ too.
  for (int i = 0; i < 9; ++i)
    out.stddev[static_cast<std::size_t>(i)] = RoundToSignificantDigits(stddev_intrinsics.at<double>(i), 4);
  out.views = static_cast<int>(object_points.size());
  out.per_view_error_px.assign(per_view.begin<double>(), per_view.end<double>());
  return out;
}

Eigen::Isometry3d BoardPose(const CameraIntrinsics& camera, const BoardGeometry& board,
                            const ChessboardDetection& detection) {
  cv::Mat rvec, tvec;
  cv::solvePnP(board.InteriorCornerPoints(), detection.corners, cv::Mat(camera.camera_matrix),
               cv::Mat(1, 5, CV_64F, const_cast<double*>(camera.distortion.data())), rvec, tvec, false,
               cv::SOLVEPNP_ITERATIVE);
  cv::Mat rotation;
  cv::Rodrigues(rvec, rotation);
  Eigen::Matrix3d r;
  Eigen::Vector3d t;
  cv::cv2eigen(rotation, r);
  cv::cv2eigen(tvec, t);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = r;
  pose.translation() = t;
  return pose;
}

PoseCovariance BoardPoseCovariance(const CameraIntrinsics& camera, const BoardGeometry& board,
                                   const ChessboardDetection& detection, const Eigen::Isometry3d& camera_from_board) {
  const auto points = board.InteriorCornerPoints();
  const int n = static_cast<int>(points.size());
  Eigen::MatrixXd jacobian(2 * n, 6);
  double squared = 0;
  constexpr double kStep = 1e-6;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d q = camera_from_board * Eigen::Vector3d(points[i].x, points[i].y, points[i].z);
    const Eigen::Vector2d at = camera.Project(q);
    squared += (at - Eigen::Vector2d(detection.corners[i].x, detection.corners[i].y)).squaredNorm();
    for (int k = 0; k < 6; ++k) {
      Eigen::Vector3d moved = q;
      if (k < 3) moved += kStep * Eigen::Vector3d::Unit(k).cross(q);  // small rotation about axis k
      else moved += kStep * Eigen::Vector3d::Unit(k - 3);
      jacobian.block<2, 1>(2 * i, k) = (camera.Project(moved) - at) / kStep;
    }
  }
  const double variance = squared / std::max(1, 2 * n - 6);
  const PoseCovariance information = jacobian.transpose() * jacobian;
  return variance * information.ldlt().solve(PoseCovariance::Identity());
}

ExtrinsicsResult RunExtrinsicsCalibration(const ExtrinsicsOptions& options, const BoardGeometry& board,
                                          const CameraIntrinsics& depth, const std::vector<ExtrinsicsView>& views,
                                          const Eigen::Isometry3d& initial) {
  const auto outline = OutlineCorners(board);
  Eigen::AngleAxisd angle_axis(initial.linear());
  double rotation[3], translation[3];
  Eigen::Vector3d::Map(rotation) = angle_axis.angle() * angle_axis.axis();
  Eigen::Vector3d::Map(translation) = initial.translation();
  std::vector<bool> used(views.size(), true);
  const auto current = [&] {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d rv = Eigen::Vector3d::Map(rotation);
    if (rv.norm() > 0) t.linear() = Eigen::AngleAxisd(rv.norm(), rv.normalized()).toRotationMatrix();
    t.translation() = Eigen::Vector3d::Map(translation);
    return t;
  };
  // A board that moves gives the colour-to-depth delay: fitted only when the
  // views' typical speed makes it observable.
  std::vector<double> speeds;
  for (const auto& v : views) speeds.push_back(v.board_velocity.norm());
  std::nth_element(speeds.begin(), speeds.begin() + static_cast<std::ptrdiff_t>(speeds.size() / 2), speeds.end());
  const bool fit_delay = !speeds.empty() && speeds[speeds.size() / 2] >= options.min_speed_for_delay_m_s;
  double delay = 0;
  const auto view_error = [&](const ExtrinsicsView& v, const Eigen::Isometry3d& depth_from_colour) {
    double sum = 0;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d at_depth_exposure =
          v.colour_from_board * outline[k] + delay * v.board_velocity;
      sum += (depth.Project(depth_from_colour * at_depth_exposure) - v.quad.corners_px[k]).squaredNorm();
    }
    return std::sqrt(sum / 4);
  };
  ExtrinsicsResult result;
  ceres::Problem problem;
  for (int round = 0; round < 2; ++round) {
    problem = ceres::Problem();
    for (std::size_t i = 0; i < views.size(); ++i) {
      if (!used[i]) continue;
      for (int k = 0; k < 4; ++k) {
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<OutlineReprojection, 2, 3, 3, 1>(new OutlineReprojection(
                views[i].colour_from_board * outline[k], views[i].quad.corners_px[k],
                views[i].board_velocity, depth)),
            new ceres::HuberLoss(1.0), rotation, translation, &delay);
      }
    }
    if (!fit_delay) problem.SetParameterBlockConstant(&delay);
    ceres::Solver::Options solver;
    solver.max_num_iterations = 50;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
    // Drop views whose outline disagrees (a mis-extracted quad), refit once.
    for (std::size_t i = 0; i < views.size(); ++i) used[i] = view_error(views[i], current()) < options.outlier_px;
  }
  result.depth_from_colour = current();
  if (fit_delay) result.delay_s = delay;
  double sum = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (!used[i]) continue;
    sum += std::pow(view_error(views[i], result.depth_from_colour), 2);
    ++result.views;
  }
  result.rms_px = result.views ? std::sqrt(sum / result.views) : 0;
  ceres::Covariance covariance({});
  const std::vector<std::pair<const double*, const double*>> blocks = {{translation, translation}};
  if (result.views >= 3 && covariance.Compute(blocks, &problem)) {
    double c[9];
    covariance.GetCovarianceBlock(translation, translation, c);
    // Residuals are pixels: scale by the per-coordinate variance (4 corners x 2 per view).
    const double variance = result.rms_px * result.rms_px / 2;
    for (int i = 0; i < 3; ++i) result.translation_sigma_m[i] = std::sqrt(std::max(0.0, c[4 * i] * variance));
  }
  return result;
}

}  // namespace speckle
