#include "apply/correction_kernel.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace speckle::apply {
namespace {

// Closed-form base forms in single precision (parameters as model/base_form.h).
struct Reciprocal {
  float a, b;
  float operator()(float r) const { return 1.0f / (a * r + b); }
};
struct Tangent {
  float c, k, b;
  float operator()(float r) const { return c * std::tan(r / k + b); }
};
struct Disparity {
  float bf8, doff;
  float operator()(float r) const { return bf8 / (doff - r); }
};
struct LinearMm {
  float a, b;
  float operator()(float r) const { return a * r + b; }
};

// Pixels per block: the block's depths stay in L1 between the two loops.
constexpr int kBlock = 512;

// Each loop is branch-free so the compiler vectorizes it: the table lookup
// becomes a gather, the validity test a blend.
template <class Base>
[[gnu::always_inline]] inline void Block(const Base& base, const KernelInput& in, int begin, int end, float* xyz,
                                         float* depth) {
  float z[kBlock];
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const int n = in.pixels;
  for (int p = begin; p < end; ++p) {
    const int r = in.raw[p];
    const float s = (static_cast<float>(r) - in.raw_lo) * in.inverse_step;
    const int k = std::min(std::max(static_cast<int>(s), 0), in.last_span);
    const float t = s - static_cast<float>(k);
    const float h0 = in.table[k * n + p], h1 = in.table[(k + 1) * n + p];
    const float value = base(h0 + t * (h1 - h0) - in.frame_offset);
    // & not &&: no short-circuit branches in the loop.
    const bool point = (r >= 1) & (r < in.no_reading_from) & (value >= in.near) & (value <= in.far);
    z[p - begin] = point ? value : nan;
  }
  if (xyz) {
    for (int p = begin; p < end; ++p) {
      const float d = z[p - begin];
      xyz[3 * p] = d * in.ray_x[p];
      xyz[3 * p + 1] = d * in.ray_y[p];
      xyz[3 * p + 2] = d;
    }
  }
  if (depth) std::copy(z, z + (end - begin), depth + begin);
}

template <class Base>
[[gnu::always_inline]] inline void Frame(const Base& base, const KernelInput& in, float* xyz, float* depth) {
  for (int begin = 0; begin < in.pixels; begin += kBlock)
    Block(base, in, begin, std::min(begin + kBlock, in.pixels), xyz, depth);
}

}  // namespace

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
// One build runs on any x86-64 and uses AVX2 or AVX-512 where the CPU has them.
__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#endif
void CorrectFrame(const KernelInput& in, float* xyz, float* depth) {
  const float* p = in.base;
  switch (in.form) {
    case model::BaseForm::kReciprocal:
      return Frame(Reciprocal{p[0], p[1]}, in, xyz, depth);
    case model::BaseForm::kTangent:
      return Frame(Tangent{p[0], p[1], p[2]}, in, xyz, depth);
    case model::BaseForm::kDisparity:
      return Frame(Disparity{p[0], p[1]}, in, xyz, depth);
    case model::BaseForm::kLinearMm:
      return Frame(LinearMm{p[0], p[1]}, in, xyz, depth);
  }
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#endif
void ColourPixels(const ColourCamera& camera, const float* xyz, int points, int* pixel) {
  // A copy: the compiler cannot tell `pixel` from the camera's fields.
  const ColourCamera c = camera;
  const float* r = c.rotation;
  const auto [k1, k2, p1, p2, k3] = c.distortion;
  const float width = static_cast<float>(c.width), height = static_cast<float>(c.height);
  // Branch-free like CorrectFrame (a NaN point fails every comparison).
  for (int p = 0; p < points; ++p) {
    const float px = xyz[3 * p], py = xyz[3 * p + 1], pz = xyz[3 * p + 2];
    const float X = r[0] * px + r[1] * py + r[2] * pz + c.translation[0];
    const float Y = r[3] * px + r[4] * py + r[5] * pz + c.translation[1];
    const float Z = r[6] * px + r[7] * py + r[8] * pz + c.translation[2];
    const float x = X / Z, y = Y / Z;
    const float r2 = x * x + y * y;
    const float radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const float xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
    const float yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
    // The nearest pixel: + 0.5, then truncation, which floors what is kept.
    const float u = c.fx * xd + c.cx + 0.5f, v = c.fy * yd + c.cy + 0.5f;
    const bool seen = (Z > 0) & (u >= 0) & (v >= 0) & (u < width) & (v < height);
    // Clamped before converting: an out-of-range conversion is undefined,
    // and one that might not run would be a branch.
    const float u_in = u < 0 ? 0 : u < width ? u : 0, v_in = v < 0 ? 0 : v < height ? v : 0;
    const int index = static_cast<int>(v_in) * c.width + static_cast<int>(u_in);
    pixel[p] = seen ? index : -1;
  }
}

}  // namespace speckle::apply
