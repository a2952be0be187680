#pragma once
// The Brown-Conrady lens model (k1, k2, p1, p2, k3) as OpenCV calibrates it,
// on normalized coordinates (x/z, y/z). One definition for the simulator and
// the stages, so both sides of every test agree on the lens.
#include <Eigen/Core>
#include <Eigen/LU>
#include <array>
#include <cmath>

namespace speckle::lens {

using Coefficients = std::array<double, 5>;

// Templated on the scalar so Ceres autodiff can differentiate through it.
template <typename T>
void Distort(const T& x, const T& y, const Coefficients& c, T* xd, T* yd) {
  const auto [k1, k2, p1, p2, k3] = c;
  const T r2 = x * x + y * y;
  const T radial = T(1) + r2 * (T(k1) + r2 * (T(k2) + r2 * T(k3)));
  *xd = x * radial + T(2 * p1) * x * y + T(p2) * (r2 + T(2) * x * x);
  *yd = y * radial + T(p1) * (r2 + T(2) * y * y) + T(2 * p2) * x * y;
}

inline Eigen::Vector2d Distort(const Eigen::Vector2d& xy, const Coefficients& c) {
  Eigen::Vector2d out;
  Distort(xy.x(), xy.y(), c, &out.x(), &out.y());
  return out;
}

// d(xd, yd) / d(x, y) of Distort.
inline Eigen::Matrix2d DistortJacobian(const Eigen::Vector2d& xy, const Coefficients& c) {
  const auto [k1, k2, p1, p2, k3] = c;
  const double x = xy.x(), y = xy.y(), r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double slope = k1 + r2 * (2 * k2 + r2 * 3 * k3);  // d radial / d r2
  Eigen::Matrix2d j;
  j << radial + 2 * x * x * slope + 2 * p1 * y + 6 * p2 * x, 2 * x * y * slope + 2 * p1 * x + 2 * p2 * y,
      2 * x * y * slope + 2 * p1 * x + 2 * p2 * y, radial + 2 * y * y * slope + 6 * p1 * y + 2 * p2 * x;
  return j;
}

// Inverse of Distort by Newton's method from the undistorted guess (every
// pixel of a session's images is undistorted: the Jacobian is analytic). NaN
// where the model has no inverse: beyond the radius where the radial
// polynomial stops growing (far corners of strong lenses), Newton would land
// on a spurious root.
inline Eigen::Vector2d Undistort(const Eigen::Vector2d& distorted, const Coefficients& c) {
  Eigen::Vector2d xy = distorted;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const Eigen::Vector2d error = Distort(xy, c) - distorted;
    if (error.squaredNorm() < 1e-24) break;
    xy -= DistortJacobian(xy, c).inverse() * error;
  }
  const auto [k1, k2, p1, p2, k3] = c;
  const double r2 = xy.squaredNorm();
  const double slope = 1 + r2 * (3 * k1 + r2 * (5 * k2 + r2 * 7 * k3));
  if ((Distort(xy, c) - distorted).norm() > 1e-9 || slope <= 0) return Eigen::Vector2d::Constant(std::nan(""));
  return xy;
}

}  // namespace speckle::lens
