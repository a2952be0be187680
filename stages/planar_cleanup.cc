#include "stages/planar_cleanup.h"

#include "schemas/option_check.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cstdio>
#include <string>

namespace speckle {

double PlanarSnapshot::TrueRaw(TrueRawMethod method, double x, double y) const {
  switch (method) {
    case TrueRawMethod::kImageMinimum:
      return true_raw_image_min;
    case TrueRawMethod::kHyperboloid:
      return true_raw_hyperboloid;
    case TrueRawMethod::kCentreMinimum:
      return true_raw_centre_min;
    case TrueRawMethod::kOwnPlane:
      return raw_plane.dot(Eigen::Vector3d(1, x, y));
  }
  return 0;
}

namespace {

// r^2 = c0 + c1 x + c2 y + c3 x^2 + c4 y^2 over the wall: the thesis's
// hyperboloid with its centre absorbed in the linear terms.
Eigen::VectorXd FitHyperboloid(const std::vector<PlanarPixel>& wall, double* sigma) {
  Eigen::MatrixXd a(static_cast<Eigen::Index>(wall.size()), 5);
  Eigen::VectorXd b(static_cast<Eigen::Index>(wall.size()));
  for (std::size_t i = 0; i < wall.size(); ++i) {
    const auto& p = wall[i];
    a.row(static_cast<Eigen::Index>(i)) << 1, p.x, p.y, p.x * p.x, p.y * p.y;
    b(static_cast<Eigen::Index>(i)) = p.raw * p.raw;
  }
  const Eigen::VectorXd c = a.colPivHouseholderQr().solve(b);
  std::vector<double> deviations;
  for (std::size_t i = 0; i < wall.size(); ++i) {
    const double model = a.row(static_cast<Eigen::Index>(i)).dot(c);
    deviations.push_back(std::abs(wall[i].raw - std::sqrt(std::max(model, 0.0))));
  }
  std::nth_element(deviations.begin(), deviations.begin() + static_cast<std::ptrdiff_t>(deviations.size() / 2),
                   deviations.end());
  *sigma = std::max(0.5, 1.4826 * deviations[deviations.size() / 2]);
  return c;
}

// The wall's own plane r = c0 + c1 x + c2 y. Billowing adds to the squared
// raw value (thesis Eq. 4.2: r_measured^2 = r^2 + bx x^2 + by y^2), so the fit
// is of r^2 = (c0 + c1 x + c2 y)^2 + even terms in x and y: the plane's
// square sets the constant, x and y terms (and the xy term with the
// billowing's), the billowing the x^2 and y^2 terms and, for adapters that
// bulge otherwise, the quartic ones. Fitted to r itself with the same even
// terms, a near wall's billowing (120 raw at the image edge at 0.35 m) tilted
// its plane by 3 raw across the image, and the grid learned the tilt.
Eigen::Vector3d FitOwnPlane(const std::vector<PlanarPixel>& wall) {
  using Row = Eigen::Matrix<double, 9, 1>;
  Eigen::Matrix<double, 9, 9> normal = Eigen::Matrix<double, 9, 9>::Zero();
  Row rhs = Row::Zero();
  for (const auto& p : wall) {
    const double x2 = p.x * p.x, y2 = p.y * p.y;
    Row row;
    row << 1, p.x, p.y, p.x * p.y, x2, y2, x2 * y2, x2 * x2, y2 * y2;
    normal += row * row.transpose();
    rhs += row * (p.raw * p.raw);
  }
  const Row q = normal.ldlt().solve(rhs);
  const double c0 = std::sqrt(std::max(q(0), 1e-12));
  return {c0, q(1) / (2 * c0), q(2) / (2 * c0)};
}

std::string Percent(double share) { return std::to_string(static_cast<int>(std::lround(100 * share))) + " %"; }

std::string Raw(double raw) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f raw", raw);
  return text;
}

std::string Degrees(double deg) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f deg", deg);
  return text;
}

}  // namespace

StageResult<PlanarSnapshot> RunPlanarCleanup(const PlanarCleanupOptions& options, const CameraIntrinsics& depth,
                                             const cv::Mat& raw, const DepthReading& reading, int frame,
                                             WallMask* segmented) {
  auto segmentation = SegmentWall(options.segmentation, depth, raw, reading, frame);
  if (auto* rejection = std::get_if<Rejection>(&segmentation)) return *rejection;
  WallSegmentation& wall = std::get<WallSegmentation>(segmentation);
  if (segmented) *segmented = wall.mask;
  PlanarSnapshot snap;
  snap.frame = frame;
  snap.valid_pixels = wall.valid_pixels;
  snap.wall_share = wall.sampled_pixels > 0 ? double(wall.wall_pixels.size()) / wall.sampled_pixels : 0;
  if (snap.wall_share < options.min_wall_share) {
    return Rejection{"planar_cleanup", "the wall covers only " + Percent(snap.wall_share) + " of the image (at least " +
                                           Percent(options.min_wall_share) +
                                           " needed): floor, ceiling, clutter or no reading fill the rest"};
  }
  if (wall.sigma_raw > options.max_wall_sigma_raw) {
    // The robust scatter the segmentation grew the wall with, not the
    // hyperboloid fit's (fit_sigma_raw in report.json), which a kept wall's
    // few stray pixels can raise past this limit: the words say which.
    return Rejection{"planar_cleanup", "failed segmentation: the region scatters " + Raw(wall.sigma_raw) +
                                           " (robust sigma about its smooth surface; one wall stays within " +
                                           Raw(options.max_wall_sigma_raw) + "): not one smooth wall"};
  }
  double sigma = 0;
  const Eigen::VectorXd c = FitHyperboloid(wall.wall_pixels, &sigma);
  snap.mask = std::move(wall.mask);
  snap.fit_sigma_raw = sigma;
  double min_all = 1e9, min_centre = 1e9, sum = 0, sum_sq = 0;
  double x_lo = 1e9, x_hi = -1e9, y_lo = 1e9, y_hi = -1e9;
  const double cx = depth.camera_matrix(0, 2), cy = depth.camera_matrix(1, 2), half = options.centre_window_px / 2.0;
  for (const auto& p : wall.wall_pixels) {
    snap.inliers.push_back(p);
    min_all = std::min(min_all, p.raw);
    x_lo = std::min(x_lo, p.x), x_hi = std::max(x_hi, p.x), y_lo = std::min(y_lo, p.y), y_hi = std::max(y_hi, p.y);
    if (std::abs(p.u - cx) <= half && std::abs(p.v - cy) <= half) min_centre = std::min(min_centre, p.raw);
    sum += p.raw;
    sum_sq += p.raw * p.raw;
  }
  snap.inlier_pixels = static_cast<int>(snap.inliers.size());
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
  snap.raw_plane = FitOwnPlane(wall.wall_pixels);
  constexpr double kNominalA = -0.0030711, kNominalB = 3.3309;  // 1/z = a r + b
  const Eigen::Vector3d normal(kNominalA * snap.raw_plane(1), kNominalA * snap.raw_plane(2),
                               kNominalA * snap.raw_plane(0) + kNominalB);
  snap.tilt_deg = std::acos(std::min(1.0, std::abs(normal.z()) / normal.norm())) * 180 / M_PI;
  if (snap.tilt_deg > options.max_wall_tilt_deg) {
    return Rejection{"planar_cleanup", "failed segmentation: the dominant plane is tilted " + Degrees(snap.tilt_deg) +
                                           " from square to the sensor (a wall is within " +
                                           Degrees(options.max_wall_tilt_deg) + "): floor, ceiling or an object"};
  }
  snap.tilt_verdict = snap.tilt_deg <= options.max_square_tilt_deg ? "square" : "tilted_wall";
  return snap;
}

bool PlanarCleanupOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .Part("segmentation", segmentation)
      .Share(min_wall_share, "min_wall_share")
      .AtLeast(max_square_tilt_deg, 0, "max_square_tilt_deg")
      .Require(max_wall_tilt_deg >= max_square_tilt_deg && max_wall_tilt_deg < 90, "max_wall_tilt_deg",
               "from max_square_tilt_deg to below 90")
      .Positive(max_wall_sigma_raw, "max_wall_sigma_raw")
      .AtLeast(centre_window_px, 1, "centre_window_px")
      .valid();
}

}  // namespace speckle
