#include "stages/tangent_form_manifold.h"

#include <algorithm>
#include <cmath>

namespace speckle {

namespace {

constexpr double kHalfPi = M_PI / 2;

// (c, k, b) -> (A, R, q); false where the form has no such coordinates.
bool ToSteps(const double* x, double* u) {
  const double c = x[0], k = x[1], b = x[2];
  if (!(c > 0) || !(k != 0) || !std::isfinite(k) || !std::isfinite(b)) return false;
  u[0] = k * c;
  u[1] = k * (kHalfPi - b);
  u[2] = c * c;
  return true;
}

}  // namespace

bool TangentFormManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  double u[3];
  if (!ToSteps(x, u)) return false;
  const double a = u[0] + delta[0], r = u[1] + delta[1], q = std::max(u[2] + delta[2], kMinQ);
  if (a == 0) return false;
  const double c = std::sqrt(q);
  x_plus_delta[0] = c;
  x_plus_delta[1] = a / c;
  x_plus_delta[2] = kHalfPi - r * c / a;
  return std::isfinite(x_plus_delta[1]) && std::isfinite(x_plus_delta[2]);
}

// d(c, k, b) / d(A, R, q), row-major 3 x 3.
bool TangentFormManifold::PlusJacobian(const double* x, double* jacobian) const {
  double u[3];
  if (!ToSteps(x, u)) return false;
  const double a = u[0], r = u[1], c = x[0], k = x[1];
  const double rows[9] = {0,
                          0,
                          1 / (2 * c),  // c = sqrt(q)
                          1 / c,
                          0,
                          -k / (2 * c * c),  // k = A / sqrt(q)
                          r * c / (a * a),
                          -c / a,
                          -r / (2 * a * c)};  // b = pi/2 - R sqrt(q) / A
  std::copy(rows, rows + 9, jacobian);
  return true;
}

bool TangentFormManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  double uy[3], ux[3];
  if (!ToSteps(y, uy) || !ToSteps(x, ux)) return false;
  for (int i = 0; i < 3; ++i) y_minus_x[i] = uy[i] - ux[i];
  return true;
}

// d(A, R, q) / d(c, k, b), row-major 3 x 3.
bool TangentFormManifold::MinusJacobian(const double* x, double* jacobian) const {
  double u[3];
  if (!ToSteps(x, u)) return false;
  const double c = x[0], k = x[1], b = x[2];
  const double rows[9] = {k,     c,           0,   // A = k c
                          0,     kHalfPi - b, -k,  // R = k (pi/2 - b)
                          2 * c, 0,           0};  // q = c^2
  std::copy(rows, rows + 9, jacobian);
  return true;
}

}  // namespace speckle
