#pragma once
// A smooth field over the depth image: a uniform bicubic B-spline with
// kNx x kNy control values spread over the VGA image. Effects use it for
// spatial patterns; the basis weights depend only on the pixel, so a field is
// linear in its control values and effects built on it give their gradient
// directly (see effect.h). The control values sum to zero (the last is
// minus the sum of the others, so kParameters = kNx kNy - 1): a constant
// field would duplicate the base form's offset and leave the fit singular.
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace speckle::model {

template <int kNx, int kNy>
struct BSplineField {
  static_assert(kNx >= 4 && kNy >= 4, "a cubic B-spline needs four control values along each axis");
  static constexpr int kControls = kNx * kNy;
  static constexpr int kParameters = kControls - 1;
  static constexpr double kWidth = 640, kHeight = 480;

  // The 4 x 4 controls whose basis functions reach a pixel: the first one's
  // column and row, and the cubic basis weights along each axis.
  struct Span {
    int su = 0, sv = 0;
    std::array<double, 4> bu{}, bv{};
    int Control(int i, int j) const { return (sv + j) * kNx + su + i; }
    double Weight(int i, int j) const { return bu[i] * bv[j]; }
  };
  static Span SpanAt(double u, double v) {
    Span span;
    double tu = 0, tv = 0;
    Locate(u, kWidth, kNx, span.su, tu);
    Locate(v, kHeight, kNy, span.sv, tv);
    span.bu = Basis(tu), span.bv = Basis(tv);
    return span;
  }

  // The field at (u, v) and, into gradient[0 .. kParameters), its derivative by
  // each control value: the basis weight of the 4 x 4 controls of this span,
  // less the last control's weight (that control is minus the sum of the others).
  static double Evaluate(const double* control, double u, double v, double* gradient) {
    const Span span = SpanAt(u, v);
    double w_last = 0;
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i)
        if (span.Control(i, j) == kControls - 1) w_last = span.Weight(i, j);
    std::fill(gradient, gradient + kParameters, -w_last);
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i)
        if (span.Control(i, j) != kControls - 1) gradient[span.Control(i, j)] += span.Weight(i, j);
    // Outside the span the gradient is -w_last (or 0): the value is linear.
    double value = 0;
    for (int k = 0; k < kParameters; ++k) value += gradient[k] * control[k];
    return value;
  }

  // Into indices, first + each control value the field at (u, v) depends on
  // (the span's 4 x 4); returns 16, or -1 when the span holds the last
  // control, which is minus the sum of all others.
  static int Support(double u, double v, int first, int* indices) {
    const Span span = SpanAt(u, v);
    int n = 0;
    for (int j = 0; j < 4; ++j) {
      for (int i = 0; i < 4; ++i) {
        if (span.Control(i, j) == kControls - 1) return -1;
        indices[n++] = first + span.Control(i, j);
      }
    }
    return n;
  }

  // The field at (u, v) from the control values Support gives, in its order,
  // and into gradient (when not null) its derivative by each of them.
  static double EvaluateOnSupport(const double* control, double u, double v, double* gradient) {
    const Span span = SpanAt(u, v);
    double value = 0;
    for (int j = 0, n = 0; j < 4; ++j) {
      for (int i = 0; i < 4; ++i, ++n) {
        value += span.Weight(i, j) * control[n];
        if (gradient) gradient[n] = span.Weight(i, j);
      }
    }
    return value;
  }

  // The field alone: only the 4 x 4 controls of the span (the last control,
  // minus the sum of the others, only when the span holds it).
  static double Evaluate(const double* control, double u, double v) {
    const Span span = SpanAt(u, v);
    double value = 0;
    for (int j = 0; j < 4; ++j) {
      for (int i = 0; i < 4; ++i) {
        const int k = span.Control(i, j);
        value += span.Weight(i, j) *
                 (k == kControls - 1 ? -std::accumulate(control, control + kParameters, 0.0) : control[k]);
      }
    }
    return value;
  }

 private:
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
};

}  // namespace speckle::model
