// How fast each board point's raw value changes, from the same point in the
// neighbouring depth frames: a board approaching at a steady rate gives that
// rate in every frame of the run (a run of two frames too), a tilted board
// sliding along its own plane gives none at a fixed pixel, a frame's own raw values never
// enter its rate where two others give it, and frames without a close
// neighbour keep 0.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "stages/raw_rate.h"

namespace speckle {
namespace {

// One run of `frames` frames 1/30 s apart from time t0, 50 board points each,
// the raw value changing at `rate` (+ a tilt of the rate over the image) with noise.
void AddRun(std::vector<PairedSample>& samples, int first_frame, int frames, double t0, double rate,
            std::mt19937_64& rng, double noise_raw) {
  std::normal_distribution<double> noise(0, noise_raw);
  for (int f = 0; f < frames; ++f) {
    for (int k = 0; k < 50; ++k) {
      PairedSample s;
      s.frame = first_frame + f;
      s.time_s = t0 + f / 30.0;
      s.board_point = k;
      s.u = 200 + 20 * (k % 10), s.v = 150 + 30 * (k / 10);
      const double point_rate = rate * (1 + 0.002 * (s.u - 320));
      s.raw = 700 + 0.3 * k + point_rate * s.time_s + noise(rng);
      samples.push_back(s);
    }
  }
}

TEST(RawRate, ASteadyRateIsMeasuredInEveryFrameOfTheRun) {
  std::mt19937_64 rng(1);
  std::vector<PairedSample> samples;
  // Noise 0.15 raw: a paired raw value is a plane through 5 x 5 pixels.
  AddRun(samples, 0, 3, 10.0, 30, rng, 0.15);   // approaching: 30 raw/s
  AddRun(samples, 3, 3, 50.0, -12, rng, 0.15);  // receding, 40 s later
  AddRun(samples, 6, 1, 90.0, 50, rng, 0.15);   // a lone frame: no rate can be measured
  AddRun(samples, 7, 2, 130.0, 20, rng, 0.15);  // a pose whose third frame was rejected
  std::map<int, double> error;                  // per frame, mean over its points
  for (const auto& s : AssignRawRates({}, samples)) {
    const double truth = s.frame < 3   ? 30 * (1 + 0.002 * (s.u - 320))
                         : s.frame < 6 ? -12 * (1 + 0.002 * (s.u - 320))
                         : s.frame < 7 ? 0
                                       : 20 * (1 + 0.002 * (s.u - 320));
    error[s.frame] += (s.raw_rate - truth) / 50;
  }
  // A frame at either end of its run takes the difference of its two
  // neighbours 1/30 s apart: 6.4 raw/s of noise per point, 0.9 raw/s on the
  // mean of 50 points. (Noise-free, every point's rate is exact.)
  ASSERT_EQ(error.size(), 9u);
  for (const auto& [frame, e] : error) EXPECT_LT(std::abs(e), 3.0) << "frame " << frame;
}

// At a fixed pixel (the joint calibration's samples), a board tilted so that
// raw rises 2 per pixel to the right, sliding right at 300 px/s along its own
// plane, shows every pixel the same raw value in every frame, while each of
// its points climbs 600 raw/s (the pairing's samples).
TEST(RawRate, ATiltedBoardSlidingAlongItsPlaneChangesNoPixel) {
  std::vector<PairedSample> samples;
  for (int f = 0; f < 3; ++f) {
    for (int k = 0; k < 50; ++k) {
      PairedSample s;
      s.frame = f;
      s.time_s = f / 30.0;
      s.board_point = k;
      s.u = 200 + 20 * (k % 10) + 300 * s.time_s, s.v = 150 + 30 * (k / 10);
      s.gradient_u = 2;
      s.raw = 700 + 2 * (s.u - 200);  // the plane of raw values stays put over the image
      samples.push_back(s);
    }
  }
  RawRateOptions at_pixel;
  at_pixel.at_fixed_pixel = true;
  for (const auto& s : AssignRawRates(at_pixel, samples)) EXPECT_NEAR(s.raw_rate, 0, 1e-9) << "frame " << s.frame;
  // The pairing's samples are off by each point's own change.
  for (const auto& s : AssignRawRates({}, samples)) EXPECT_NEAR(s.raw_rate, 600, 1e-6) << "frame " << s.frame;
}

TEST(RawRate, AFramesOwnRawValuesDoNotEnterItsRate) {
  std::mt19937_64 rng(2);
  std::vector<PairedSample> samples;
  AddRun(samples, 0, 3, 0.0, 0, rng, 0.0);
  const auto before = AssignRawRates({}, samples);
  for (auto& s : samples)
    if (s.frame == 1) s.raw += 5;  // the middle frame alone reads 5 raw higher
  const auto after = AssignRawRates({}, samples);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (samples[i].frame == 1) {
      EXPECT_DOUBLE_EQ(after[i].raw_rate, before[i].raw_rate);
    }
  }
}

TEST(RawRate, BoardPlanePixelsAndFramesFarApartKeepZero) {
  std::mt19937_64 rng(3);
  std::vector<PairedSample> samples;
  AddRun(samples, 0, 1, 0.0, 30, rng, 0.3);
  AddRun(samples, 1, 1, 0.5, 30, rng, 0.3);  // half a second later: another pose
  AddRun(samples, 2, 1, 1.0, 30, rng, 0.3);
  for (auto& s : samples) s.board_point = s.frame == 2 ? -1 : s.board_point;
  for (const auto& s : AssignRawRates({}, samples)) EXPECT_EQ(s.raw_rate, 0) << "frame " << s.frame;
}

}  // namespace
}  // namespace speckle
