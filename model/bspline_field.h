#pragma once
// A smooth field over the depth image: a uniform bicubic B-spline with
// kNx x kNy control values spread over the VGA image. Effects use it for
// spatial patterns; the basis weights depend only on the pixel, so a field is
// linear in its control values. The control values sum to zero (the last is
// minus the sum of the others, so kParameters = kNx kNy - 1): a constant
// field would duplicate the base form's offset and leave the fit singular.
#include <algorithm>
#include <array>
#include <cmath>

namespace speckle::model {

template <int kNx, int kNy>
struct BSplineField {
  static_assert(kNx >= 4 && kNy >= 4, "a cubic B-spline needs four control values along each axis");
  static constexpr int kControls = kNx * kNy;
  static constexpr int kParameters = kControls - 1;
  static constexpr double kWidth = 640, kHeight = 480;

  // Cubic B-spline basis weights at t in [0, 1) of one span.
  static std::array<double, 4> Basis(double t) {
    const double s = 1 - t;
    return {s * s * s / 6, (3 * t * t * t - 6 * t * t + 4) / 6, (-3 * t * t * t + 3 * t * t + 3 * t + 1) / 6,
            t * t * t / 6};
  }
  // The span and position within it, clamped so the image edge uses the last span.
  static void Locate(double coordinate, double extent, int controls, int& span, double& t) {
    const double spans = controls - 3;
    const double s = std::clamp(coordinate / extent * spans, 0.0, spans - 1e-9);
    span = static_cast<int>(s);
    t = s - span;
  }

  template <typename T>
  static T Evaluate(const T* control, double u, double v) {
    int su = 0, sv = 0;
    double tu = 0, tv = 0;
    Locate(u, kWidth, kNx, su, tu);
    Locate(v, kHeight, kNy, sv, tv);
    const auto bu = Basis(tu), bv = Basis(tv);
    std::array<double, kControls> weight{};
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) weight[(sv + j) * kNx + su + i] = bu[i] * bv[j];
    T value(0);
    for (int k = 0; k < kParameters; ++k) {
      const double w = weight[k] - weight[kControls - 1];
      if (w != 0) value += w * control[k];
    }
    return value;
  }
};

}  // namespace speckle::model
