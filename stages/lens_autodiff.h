#pragma once
// The Brown-Conrady lens (k1, k2, p1, p2, k3) for Ceres' autodiff, shared
// by every fit that differentiates through a camera: the outline
// calibration's board planes (stages/outline_calibration.cc) and the joint
// calibration (lab/joint/joint_residuals.h). A camera is (fx, fy, cx, cy).
#include <ceres/jet.h>

namespace speckle {

// A camera-frame point to its pixel, through the lens.
template <typename T>
void Project(const T* k, const T* lens, const T* q, T* pixel) {
  const T x = q[0] / q[2], y = q[1] / q[2];
  const T r2 = x * x + y * y;
  const T scale = T(1) + r2 * (lens[0] + r2 * (lens[1] + r2 * lens[4]));
  const T xd = x * scale + T(2) * lens[2] * x * y + lens[3] * (r2 + T(2) * x * x);
  const T yd = y * scale + lens[2] * (r2 + T(2) * y * y) + T(2) * lens[3] * x * y;
  pixel[0] = k[0] * xd + k[2];
  pixel[1] = k[1] * yd + k[3];
}

// A value without its derivatives.
inline double ValueOf(double x) { return x; }
template <typename T, int N>
double ValueOf(const ceres::Jet<T, N>& x) {
  return ValueOf(x.a);
}

// A pixel to its normalized undistorted coordinates: the fixed-point
// iteration and Newton's in plain numbers, then one more Newton step of the
// lens's projection in T, which carries the derivatives by the
// implicit function theorem. Differentiating the ten steps themselves was
// most of a depth sample's cost in the joint fit.
template <typename T>
void Undistort(const T* k, const T* lens, double u, double v, T* xy) {
  double kd[4], ld[5];
  for (int i = 0; i < 4; ++i) kd[i] = ValueOf(k[i]);
  for (int i = 0; i < 5; ++i) ld[i] = ValueOf(lens[i]);
  const double xd = (u - kd[2]) / kd[0], yd = (v - kd[3]) / kd[1];
  double x = xd, y = yd;
  for (int i = 0; i < 10; ++i) {
    const double r2 = x * x + y * y;
    const double scale = 1 + r2 * (ld[0] + r2 * (ld[1] + r2 * ld[4]));
    const double x_next = (xd - 2 * ld[2] * x * y - ld[3] * (r2 + 2 * x * x)) / scale;
    y = (yd - ld[2] * (r2 + 2 * y * y) - 2 * ld[3] * x * y) / scale;
    x = x_next;
  }
  // Two Newton steps in plain numbers finish what the iteration leaves (1e-8
  // px at a wide lens's corner); the projection's 2 x 2 derivative by (x, y)
  // is the last one's.
  double a = 1, b = 0, c = 0, d = 1, det = 1;
  using J2 = ceres::Jet<double, 2>;
  const J2 k2[4] = {J2(kd[0]), J2(kd[1]), J2(kd[2]), J2(kd[3])};
  const J2 l2[5] = {J2(ld[0]), J2(ld[1]), J2(ld[2]), J2(ld[3]), J2(ld[4])};
  for (int step = 0; step < 2; ++step) {
    const J2 q2[3] = {J2(x, 0), J2(y, 1), J2(1.0)};
    J2 p2[2];
    Project(k2, l2, q2, p2);
    a = p2[0].v[0], b = p2[0].v[1], c = p2[1].v[0], d = p2[1].v[1], det = a * d - b * c;
    const double du = p2[0].a - u, dv = p2[1].a - v;
    x -= (d * du - b * dv) / det;
    y -= (a * dv - c * du) / det;
  }
  // The pixel's miss (zero in value where the iteration converged) in T.
  const T q[3] = {T(x), T(y), T(1)};
  T pixel[2];
  Project(k, lens, q, pixel);
  const T du = pixel[0] - T(u), dv = pixel[1] - T(v);
  xy[0] = T(x) - (d * du - b * dv) / det;
  xy[1] = T(y) - (a * dv - c * du) / det;
}

}  // namespace speckle
