#pragma once
// The per-frame inner loop of DepthCorrector: raw value -> table lookup ->
// base form -> point, for every pixel. Kept apart so it can be compiled for
// the vector units the machine has (AVX2 gathers, AVX-512) and measured
// alone (bench/bench_apply.cc).
#include <cstddef>
#include <cstdint>

#include "model/base_form.h"

namespace speckle::apply {

struct KernelInput {
  const std::uint16_t* raw = nullptr;
  int pixels = 0;
  const float* table = nullptr;  // [knot][pixel] corrected raw values (NaN: no ray)
  const float* ray_x = nullptr;  // per pixel
  const float* ray_y = nullptr;
  float raw_lo = 0, inverse_step = 1;  // knot k sits at raw_lo + k / inverse_step
  int last_span = 0;                   // knots - 2
  float frame_offset = 0;              // the effects of time alone, in raw units
  float near = 0, far = 0;             // metres; outside: no point
  int no_reading_from = 2047;          // raw values >= this (or 0) are no reading
  model::BaseForm form = model::BaseForm::kReciprocal;
  float base[model::kMaxBaseParameters] = {};
};

// Writes 3 floats per pixel to xyz and/or one to depth (either may be null);
// NaN where there is no point.
void CorrectFrame(const KernelInput& in, float* xyz, float* depth);

struct ColourCamera {
  float rotation[9];     // colour from depth, row-major
  float translation[3];  // metres
  float fx, fy, cx, cy;
  float distortion[5];  // k1 k2 p1 p2 k3
  int width, height;
};

// The colour pixel (row-major index) each point is seen at, -1 where none (no
// point, behind the camera, outside the image); nearest pixel.
void ColourPixels(const ColourCamera& camera, const float* xyz, int points, int* pixel);

}  // namespace speckle::apply
