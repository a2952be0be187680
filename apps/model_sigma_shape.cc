#include "apps/model_sigma_shape.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "model/depth_model.h"

namespace speckle {
namespace {

// A node's pixel along one axis: every step, and the last pixel.
double NodePixel(int i, int step, int size) { return std::min(i * step, size - 1); }

model::Covariates At(const apply::DepthCalibration& c, double u, double v, double raw) {
  model::Covariates covariates;
  covariates.raw = raw, covariates.u = u, covariates.v = v;
  const Eigen::Vector2d ray = c.depth.Ray(u, v);
  covariates.x = ray.x(), covariates.y = ray.y();
  return covariates;
}

}  // namespace

double ModelSigmaShape::At(double u, double v) const {
  if (factor.empty()) return 1;
  const double fu = std::clamp(u / step_px, 0.0, cells_u - 1.0), fv = std::clamp(v / step_px, 0.0, cells_v - 1.0);
  const int i = std::min(static_cast<int>(fu), cells_u - 2), j = std::min(static_cast<int>(fv), cells_v - 2);
  const double tu = fu - i, tv = fv - j;
  const auto f = [&](int a, int b) { return factor[static_cast<std::size_t>(b) * cells_u + a]; };
  return (1 - tv) * ((1 - tu) * f(i, j) + tu * f(i + 1, j)) + tv * ((1 - tu) * f(i, j + 1) + tu * f(i + 1, j + 1));
}

ModelSigmaShape ModelSigmaShapeAt(const apply::DepthCalibration& calibration, const std::vector<double>& covariance,
                                  double raw, int step_px) {
  ModelSigmaShape shape;
  const model::DepthModel& m = *calibration.model;
  const std::vector<double> flat = m.Flat();
  const std::size_t np = flat.size();
  const int width = calibration.depth.width, height = calibration.depth.height;
  if (np == 0 || covariance.size() != np * np || width < 2 || height < 2) return shape;
  shape.width = width, shape.height = height, shape.step_px = step_px;
  shape.cells_u = (width - 1 + step_px - 1) / step_px + 1, shape.cells_v = (height - 1 + step_px - 1) / step_px + 1;
  // The nodes, then the centre last.
  std::vector<model::Covariates> points;
  for (int j = 0; j < shape.cells_v; ++j)
    for (int i = 0; i < shape.cells_u; ++i)
      points.push_back(At(calibration, NodePixel(i, step_px, width), NodePixel(j, step_px, height), raw));
  points.push_back(At(calibration, 0.5 * width, 0.5 * height, raw));
  const auto n = static_cast<Eigen::Index>(points.size());
  Eigen::VectorXd depth(n);
  for (Eigen::Index k = 0; k < n; ++k) depth(k) = m.Depth(points[static_cast<std::size_t>(k)]);
  // Each parameter's numeric derivative at every point at once (one SetFlat a parameter).
  Eigen::MatrixXd gradient(static_cast<Eigen::Index>(np), n);
  model::DepthModel moved = m;
  std::vector<double> p = flat;
  for (std::size_t i = 0; i < np; ++i) {
    const double h = 1e-6 * std::max(1e-6, std::abs(p[i]));
    p[i] = flat[i] + h;
    moved.SetFlat(p);
    for (Eigen::Index k = 0; k < n; ++k)
      gradient(static_cast<Eigen::Index>(i), k) = (moved.Depth(points[static_cast<std::size_t>(k)]) - depth(k)) / h;
    p[i] = flat[i];
  }
  const auto c = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      covariance.data(), static_cast<Eigen::Index>(np), static_cast<Eigen::Index>(np));
  const Eigen::VectorXd variance = (c * gradient).cwiseProduct(gradient).colwise().sum().transpose();
  const double centre = variance(n - 1);
  if (!(centre > 0) || !std::isfinite(centre)) return {};
  shape.factor.resize(static_cast<std::size_t>(n - 1));
  for (Eigen::Index k = 0; k + 1 < n; ++k) {
    const double ratio = std::sqrt(std::max(0.0, variance(k)) / centre);
    // A node where the model gives no depth (beyond the lens model's radius) takes the centre's.
    shape.factor[static_cast<std::size_t>(k)] = std::isfinite(ratio) ? ratio : 1.0;
  }
  return shape;
}

}  // namespace speckle
