#include "stages/camera_calibration.h"

#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/core/version.hpp>

#include "schemas/errors.h"
#include "schemas/option_check.h"
#include "stages/significant_digits.h"

namespace speckle {
namespace {

// calibrateCamera's sigmas before OpenCV 4.7 take the residual variance as
// the squared errors over (points - parameters), where each point gives two
// residuals: over (2 points - parameters). Their sigmas are then about
// sqrt(2) too large (opencv/opencv#19803, fixed by PR #22992 in 4.7). The
// factor that turns theirs into the unbiased ones; 1 from 4.7 on.
double OpenCvSigmaCorrection(const std::vector<std::vector<cv::Point3f>>& object_points, bool fix_k3) {
#if CV_VERSION_MAJOR > 4 || (CV_VERSION_MAJOR == 4 && CV_VERSION_MINOR >= 7)
  (void)object_points, (void)fix_k3;
  return 1.0;
#else
  double points = 0;
  for (const auto& view : object_points) points += static_cast<double>(view.size());
  // Free parameters: fx, fy, cx, cy, k1, k2, p1, p2 (and k3), 6 per view.
  const double parameters = (fix_k3 ? 8 : 9) + 6.0 * static_cast<double>(object_points.size());
  return std::sqrt((points - parameters) / (2 * points - parameters));
#endif
}

}  // namespace

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
  out.rms_reprojection_px = cv::calibrateCamera(object_points, image_points, out.image_size, camera_matrix, distortion,
                                                rvecs, tvecs, stddev_intrinsics, stddev_extrinsics, per_view, flags);
  out.camera_matrix = cv::Matx33d(camera_matrix);
  for (int i = 0; i < 5; ++i) out.distortion[static_cast<std::size_t>(i)] = distortion.at<double>(i);
  // Four significant digits: the standard deviations come from an
  // ill-conditioned inverse whose last bits follow the memory layout (OpenCV
  // and BLAS kernels), so the same views gave values differing by 4e-6 from
  // run to run; the camera perturbations, parameter sigmas and noise floor
  // built on them would differ too.
  const double scale = OpenCvSigmaCorrection(object_points, options.fix_k3);
  for (int i = 0; i < 9; ++i)
    out.stddev[static_cast<std::size_t>(i)] = RoundToSignificantDigits(scale * stddev_intrinsics.at<double>(i), 4);
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

namespace {

// The mean of (d d^T) over the poses of the detection's other refinements,
// d their (w, dt) from `camera_from_board` as BoardPoseCovariance defines
// them: a pose that changes with an admissible refinement window is not
// known better than that change. Far boards behind a blurring lens (room
// seeds 14, 22 and 36) had colour poses 2-3.4 mm off in depth; the windows'
// poses moved them 0.9-1.7 mm, and each frame's depth error over its stated
// sigma went from an RMS of 1.04-1.30 to 0.79-0.91 with this term.
PoseCovariance RefinementSpread(const CameraIntrinsics& camera, const BoardGeometry& board,
                                const ChessboardDetection& detection, const Eigen::Isometry3d& camera_from_board) {
  PoseCovariance spread = PoseCovariance::Zero();
  for (const auto& corners : detection.other_refinements) {
    const Eigen::Isometry3d other = BoardPose(camera, board, ChessboardDetection{corners, detection.image_size, {}});
    const Eigen::AngleAxisd turn(other.linear() * camera_from_board.linear().transpose());
    const Eigen::Vector3d w = turn.angle() * turn.axis();
    Eigen::Matrix<double, 6, 1> d;
    d << w, other.translation() - camera_from_board.translation() - w.cross(camera_from_board.translation());
    spread += d * d.transpose();
  }
  if (!detection.other_refinements.empty()) spread /= static_cast<double>(detection.other_refinements.size());
  return spread;
}

}  // namespace

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
      if (k < 3)
        moved += kStep * Eigen::Vector3d::Unit(k).cross(q);  // small rotation about axis k
      else
        moved += kStep * Eigen::Vector3d::Unit(k - 3);
      jacobian.block<2, 1>(2 * i, k) = (camera.Project(moved) - at) / kStep;
    }
  }
  const double variance = squared / std::max(1, 2 * n - 6);
  const PoseCovariance information = jacobian.transpose() * jacobian;
  return variance * information.ldlt().solve(PoseCovariance::Identity()) +
         RefinementSpread(camera, board, detection, camera_from_board);
}

bool IntrinsicsOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .AtLeast(min_views, 3, "min_views")
      .Require(max_views >= min_views, "max_views", ">= min_views")
      .valid();
}

}  // namespace speckle
