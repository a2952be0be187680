#pragma once
// The steps of a tangent base form's fit, taken in coordinates where its
// valley ends. Magnenat's raw = k (atan(z / c) - b) approaches the reciprocal
// form as c -> 0 with k c and k (pi/2 - b) fixed (atan(z/c) = pi/2 -
// atan(c/z)). On a sensor the reciprocal form describes, the best fit lies
// at the end of that valley, where k and b run off to infinity: stepping in
// (c, k, b) the fit ran to its 100-iteration limit at every fold, most of
// the comparison fits' time, and stopped wherever the limit left it.
//
// Steps are taken in (A, R, t): A = k c, R = k (pi/2 - b), and t a
// coordinate of q = c^2. In (A, R, q) the form is raw = R - A atan(sqrt(q) /
// z) / sqrt(q) = R - A / z + A q / (3 z^3) - ...: nearly linear, with the
// reciprocal limit at q = 0. q is held above kMinQ (c >= 0.1 mm, where the
// form differs from the reciprocal one by 1e-5 raw) so that the stored
// (c, k, b) stay finite. t is q - kMinQ down to a knee at 1e-6 m^2 and
// exponential below it, rather than q clamped at kMinQ: a clamped step is
// not the step the solver's linear model took, and where the fit ends at the
// limit every step was clamped, so it crept there in dozens of iterations at
// a trust-region ratio of 0.1 (Herrera's undistorted samples: 72; a stock
// 60-frame session's folds: 10x the reciprocal form's time).
#include <ceres/manifold.h>

namespace speckle {

class TangentFormManifold : public ceres::Manifold {
 public:
  static constexpr double kMinQ = 1e-8;  // m^2
  int AmbientSize() const override { return 3; }
  int TangentSize() const override { return 3; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

}  // namespace speckle
