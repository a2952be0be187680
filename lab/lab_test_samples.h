#pragma once
// Synthetic paired samples drawn from a known depth model, shared by the
// lab's tests: 30 still poses of 3 frames, 40 board points each, over 15
// minutes; raw values from the reciprocal truth plus `extra` plus noise (per
// frame and per sample).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "lab/diagnosis/diagnosis.h"
#include "lab/diagnosis/verdict_text.h"
#include "lab/fit/depth_fit.h"

namespace speckle {

inline model::EffectSpec Named(const std::string& name) {
  model::EffectSpec e;
  e.name = name;
  return e;
}

// The verdict as the apps write it for a session named S.
inline std::string Words(const Diagnosis& d) { return VerdictText(d, "S"); }

inline std::vector<PairedSample> Synthetic(std::uint64_t seed,
                                           const std::function<double(const PairedSample&)>& extra) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0, 1);
  std::uniform_real_distribution<double> uniform(0, 1);
  const double a = -0.0027681, b = 3.0163;
  std::vector<PairedSample> samples;
  int frame = 0;
  for (int pose = 0; pose < 30; ++pose) {
    const double z0 = 0.6 + 0.9 * uniform(rng), tilt = 0.3 * (uniform(rng) - 0.5);
    const double cu = 150 + 340 * uniform(rng), cv = 120 + 240 * uniform(rng);
    const double vu = 20 * noise(rng), vv = 20 * noise(rng);
    for (int f = 0; f < 3; ++f, ++frame) {
      const double frame_error = 0.15 * noise(rng);  // a colour pose's depth error, in raw units
      for (int k = 0; k < 40; ++k) {
        PairedSample s;
        s.frame = frame, s.pose = pose, s.board_point = k;
        s.time_s = pose * 30 + f / 30.0;
        s.u = cu + (k % 8 - 3.5) * 14, s.v = cv + (k / 8 - 2) * 14;
        s.x = (s.u - 320) / 580, s.y = (s.v - 240) / 580;
        s.depth_m = z0 * (1 + tilt * s.x);
        const double base = (1 / s.depth_m - b) / a;
        s.gradient_u = tilt * 1.5, s.gradient_v = 0.2;
        s.velocity_u = vu, s.velocity_v = vv;
        s.raw_rate = vu;  // a swaying board: tens of raw units per second
        s.albedo = k % 3 == 0 ? 0.0 : (k % 3 == 1 ? 1.0 : 0.5);
        s.raw = base;
        s.raw = base + extra(s) + frame_error + 0.3 * noise(rng);
        samples.push_back(s);
      }
    }
  }
  return samples;
}

inline DepthFit Fit(const model::ModelDefinition& definition, const std::vector<PairedSample>& samples) {
  auto fit = RunDepthModelFit(DepthFitOptions{}, definition, samples);
  EXPECT_TRUE(Accepted(fit)) << (Accepted(fit) ? "" : std::get<Rejection>(fit).reason);
  return std::get<DepthFit>(fit);
}

// The true depths from a miscalibrated camera: tilted by `tilt` across the
// image, as an IR principal point that is off tilts them through the
// extrinsics. The perturbations hold that camera input's one-sigma tilt
// (sigma_tilt) and a one-sigma scale, as calibration_run.cc writes them.
struct TiltedTruth {
  std::vector<PairedSample> samples;
  DepthPerturbations perturbations;
};
inline TiltedTruth Tilted(double tilt, double sigma_tilt) {
  TiltedTruth t;
  t.samples = Synthetic(5, [](const PairedSample&) { return 0.0; });
  t.perturbations.depths.resize(2);
  for (auto& s : t.samples) {
    s.depth_m *= 1 + tilt * s.x;
    t.perturbations.depths[0].push_back(s.depth_m * (1 + sigma_tilt * s.x));
    t.perturbations.depths[1].push_back(s.depth_m * 1.001);
  }
  return t;
}

}  // namespace speckle
