#include "stages/planar_cleanup.h"

#include <Eigen/Dense>
#include <algorithm>

namespace speckle {

double PlanarSnapshot::TrueRaw(TrueRawMethod method, double x, double y) const {
  switch (method) {
    case TrueRawMethod::kImageMinimum: return true_raw_image_min;
    case TrueRawMethod::kHyperboloid: return true_raw_hyperboloid;
    case TrueRawMethod::kCentreMinimum: return true_raw_centre_min;
    case TrueRawMethod::kOwnPlane: return raw_plane.dot(Eigen::Vector3d(1, x, y));
  }
  return 0;
}

StageResult<PlanarSnapshot> RunPlanarCleanup(const PlanarCleanupOptions& options, const CameraIntrinsics& depth,
                                             const cv::Mat& raw, int frame) {
  if (raw.empty()) return Rejection{"planar_cleanup", "no depth image in this frame"};
  std::vector<PlanarPixel> pixels;
  for (int v = options.crop_px; v < raw.rows - options.crop_px; v += options.stride) {
    for (int u = options.crop_px; u < raw.cols - options.crop_px; u += options.stride) {
      const std::uint16_t r = raw.at<std::uint16_t>(v, u);
      if (!options.reading.IsReading(r)) continue;
      const Eigen::Vector2d xy = depth.Undistort({u, v});
      if (!xy.allFinite()) continue;
      pixels.push_back({double(u), double(v), xy.x(), xy.y(), double(r)});
    }
  }
  PlanarSnapshot snap;
  snap.frame = frame;
  snap.valid_pixels = static_cast<int>(pixels.size());
  if (pixels.size() < 500) return Rejection{"planar_cleanup", "too few valid pixels for a wall"};

  // r^2 = c0 + c1 x + c2 y + c3 x^2 + c4 y^2: the hyperboloid with its centre
  // absorbed in the linear terms. Start from the pixels near the median raw.
  std::vector<double> sorted;
  for (const auto& p : pixels) sorted.push_back(p.raw);
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double median = sorted[sorted.size() / 2];
  std::vector<bool> inlier(pixels.size());
  for (std::size_t i = 0; i < pixels.size(); ++i) inlier[i] = std::abs(pixels[i].raw - median) < 40 * options.reading.UnitsPerRawStep(median);
  Eigen::VectorXd c(5);
  double sigma = 0;
  for (int round = 0; round < 6; ++round) {
    int n = static_cast<int>(std::count(inlier.begin(), inlier.end(), true));
    if (n < 100) return Rejection{"planar_cleanup", "no dominant plane among the valid pixels"};
    Eigen::MatrixXd a(n, 5);
    Eigen::VectorXd b(n);
    int row = 0;
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      if (!inlier[i]) continue;
      const auto& p = pixels[i];
      a.row(row) << 1, p.x, p.y, p.x * p.x, p.y * p.y;
      b(row++) = p.raw * p.raw;
    }
    c = a.colPivHouseholderQr().solve(b);
    std::vector<double> deviations;
    std::vector<double> residual(pixels.size());
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      const auto& p = pixels[i];
      const double model = c(0) + c(1) * p.x + c(2) * p.y + c(3) * p.x * p.x + c(4) * p.y * p.y;
      residual[i] = p.raw - std::sqrt(std::max(model, 0.0));
      if (inlier[i]) deviations.push_back(std::abs(residual[i]));
    }
    std::nth_element(deviations.begin(), deviations.begin() + static_cast<std::ptrdiff_t>(deviations.size() / 2),
                     deviations.end());
    sigma = std::max(0.5, 1.4826 * deviations[deviations.size() / 2]);
    for (std::size_t i = 0; i < pixels.size(); ++i) inlier[i] = std::abs(residual[i]) < options.inlier_sigmas * sigma;
  }
  snap.fit_sigma_raw = sigma;
  double min_all = 1e9, min_centre = 1e9, sum = 0, sum_sq = 0;
  double x_lo = 1e9, x_hi = -1e9, y_lo = 1e9, y_hi = -1e9;
  // r = c0 + c1 x + c2 y + c3 rho^2 + c4 rho^4: the plane, with the radial
  // terms of lens billowing beside it so they do not pass for tilt.
  Eigen::Matrix<double, 5, 5> plane_normal = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::Matrix<double, 5, 1> plane_rhs = Eigen::Matrix<double, 5, 1>::Zero();
  const double cx = depth.camera_matrix(0, 2), cy = depth.camera_matrix(1, 2), half = options.centre_window_px / 2.0;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    if (!inlier[i]) continue;
    const auto& p = pixels[i];
    snap.inliers.push_back(p);
    min_all = std::min(min_all, p.raw);
    x_lo = std::min(x_lo, p.x), x_hi = std::max(x_hi, p.x), y_lo = std::min(y_lo, p.y), y_hi = std::max(y_hi, p.y);
    if (std::abs(p.u - cx) <= half && std::abs(p.v - cy) <= half) min_centre = std::min(min_centre, p.raw);
    sum += p.raw;
    sum_sq += p.raw * p.raw;
    const double rho2 = p.x * p.x + p.y * p.y;
    Eigen::Matrix<double, 5, 1> row;
    row << 1, p.x, p.y, rho2, rho2 * rho2;
    plane_normal += row * row.transpose();
    plane_rhs += row * p.raw;
  }
  snap.inlier_pixels = static_cast<int>(snap.inliers.size());
  if (snap.inlier_pixels < options.min_inlier_share * snap.valid_pixels) {
    return Rejection{"planar_cleanup", "the dominant plane covers only " + std::to_string(snap.inlier_pixels) + " of " +
                                           std::to_string(snap.valid_pixels) + " valid pixels"};
  }
  const double n = snap.inlier_pixels;
  snap.raw_sigma_before = std::sqrt(std::max(0.0, sum_sq / n - (sum / n) * (sum / n)));
  snap.true_raw_image_min = min_all;
  snap.true_raw_centre_min = min_centre < 1e9 ? min_centre : min_all;
  // The hyperboloid's vertex: the minimum of the fitted r^2 surface, kept on
  // the wall. With little billowing (stock optics) the curvature is noise
  // and a slight ramp sends the vertex tens of image widths away, where the
  // surface extrapolates 15-20 raw below every pixel of the wall.
  const double x0 = c(3) > 1e-9 ? std::clamp(-c(1) / (2 * c(3)), x_lo, x_hi) : 0;
  const double y0 = c(4) > 1e-9 ? std::clamp(-c(2) / (2 * c(4)), y_lo, y_hi) : 0;
  const double vertex = c(0) + c(1) * x0 + c(2) * y0 + c(3) * x0 * x0 + c(4) * y0 * y0;
  snap.true_raw_hyperboloid = std::sqrt(std::max(vertex, 0.0));
  snap.raw_plane = plane_normal.ldlt().solve(plane_rhs).head<3>();
  constexpr double kNominalA = -0.0030711, kNominalB = 3.3309;  // 1/z = a r + b
  const Eigen::Vector3d normal(kNominalA * snap.raw_plane(1), kNominalA * snap.raw_plane(2),
                               kNominalA * snap.raw_plane(0) + kNominalB);
  snap.tilt_deg = std::acos(std::min(1.0, std::abs(normal.z()) / normal.norm())) * 180 / M_PI;
  return snap;
}

}  // namespace speckle
