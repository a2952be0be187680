#include "lab/fit/tangent_form_manifold.h"

#include <algorithm>
#include <cmath>

namespace speckle {

namespace {

constexpr double kHalfPi = M_PI / 2;

// The third step coordinate t is q - kMinQ itself above kKnee, and below it
// kKnee exp(t / kKnee - 1), which meets it with the same slope at kKnee and
// reaches kMinQ only as t -> -inf. Linear where a fit usually ends (c of
// centimetres, q ~ 1e-2 m^2), so it lands there in as few steps as in q;
// smooth down to the reciprocal limit, so no step there is clamped.
constexpr double kKnee = 1e-6;  // m^2: c = 1 mm
// q - kMinQ is read as at least this, so that t stays finite where a fit
// left q at kMinQ.
constexpr double kMinExcess = 1e-6 * TangentFormManifold::kMinQ;

double ExcessOf(double t) { return t >= kKnee ? t : kKnee * std::exp(t / kKnee - 1); }
double CoordinateOf(double excess) {
  excess = std::max(excess, kMinExcess);
  return excess >= kKnee ? excess : kKnee * (1 + std::log(excess / kKnee));
}
// dq / dt at an excess q - kMinQ.
double Slope(double excess) { return std::min(1.0, std::max(excess, kMinExcess) / kKnee); }

// (c, k, b) -> (A, R, t); false where the form has no such coordinates.
bool ToSteps(const double* x, double* u) {
  const double c = x[0], k = x[1], b = x[2];
  if (!(c > 0) || !(k != 0) || !std::isfinite(k) || !std::isfinite(b)) return false;
  u[0] = k * c;
  u[1] = k * (kHalfPi - b);
  u[2] = CoordinateOf(c * c - TangentFormManifold::kMinQ);
  return true;
}

double ExcessAt(const double* x) { return x[0] * x[0] - TangentFormManifold::kMinQ; }

}  // namespace

bool TangentFormManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  double u[3];
  if (!ToSteps(x, u)) return false;
  const double a = u[0] + delta[0], r = u[1] + delta[1], q = kMinQ + ExcessOf(u[2] + delta[2]);
  if (a == 0) return false;
  const double c = std::sqrt(q);
  x_plus_delta[0] = c;
  x_plus_delta[1] = a / c;
  x_plus_delta[2] = kHalfPi - r * c / a;
  return std::isfinite(x_plus_delta[1]) && std::isfinite(x_plus_delta[2]);
}

// d(c, k, b) / d(A, R, t), row-major 3 x 3 (e = dq / dt).
bool TangentFormManifold::PlusJacobian(const double* x, double* jacobian) const {
  double u[3];
  if (!ToSteps(x, u)) return false;
  const double a = u[0], r = u[1], c = x[0], k = x[1], e = Slope(ExcessAt(x));
  const double rows[9] = {0,
                          0,
                          e / (2 * c),  // c = sqrt(q)
                          1 / c,
                          0,
                          -k * e / (2 * c * c),  // k = A / sqrt(q)
                          r * c / (a * a),
                          -c / a,
                          -r * e / (2 * a * c)};  // b = pi/2 - R sqrt(q) / A
  std::copy(rows, rows + 9, jacobian);
  return true;
}

bool TangentFormManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  double uy[3], ux[3];
  if (!ToSteps(y, uy) || !ToSteps(x, ux)) return false;
  for (int i = 0; i < 3; ++i) y_minus_x[i] = uy[i] - ux[i];
  return true;
}

// d(A, R, t) / d(c, k, b), row-major 3 x 3.
bool TangentFormManifold::MinusJacobian(const double* x, double* jacobian) const {
  double u[3];
  if (!ToSteps(x, u)) return false;
  const double c = x[0], k = x[1], b = x[2];
  // clang-format off
  const double rows[9] = {k,                          c,           0,   // A = k c
                          0,                          kHalfPi - b, -k,  // R = k (pi/2 - b)
                          2 * c / Slope(ExcessAt(x)), 0,           0};  // t of q = c^2
  // clang-format on
  std::copy(rows, rows + 9, jacobian);
  return true;
}

}  // namespace speckle
