#include "stages/raw_rate.h"

#include "schemas/option_check.h"
#include "stages/rate_neighbours.h"

#include <Eigen/Dense>
#include <map>
#include <unordered_map>

namespace speckle {
namespace {

// A board point's raw value in two frames changes by how fast the depth
// image changes at a fixed pixel, plus the raw gradient along the path the
// point took over the image; the first alone where `at_fixed_pixel`. On the
// joint calibration's samples the point's own change missed the hidden
// delay's offsets by 0.5 raw rms of 1.5 (the hunt's capture_time_offset seed
// 1); on the pairing's, the change at a fixed pixel left 0.78 raw where the
// point's own left 0.49 (effect_capture_time_offset.json seed 1).
double PointRate(const PairedSample& before, const PairedSample& after, double dt, bool at_fixed_pixel) {
  double change = after.raw - before.raw;
  if (at_fixed_pixel)
    change -= 0.5 * (before.gradient_u + after.gradient_u) * (after.u - before.u) +
              0.5 * (before.gradient_v + after.gradient_v) * (after.v - before.v);
  return change / dt;
}

}  // namespace

std::vector<PairedSample> AssignRawRates(const RawRateOptions& options, std::vector<PairedSample> samples) {
  struct FrameSamples {
    double time_s = 0;
    std::vector<std::size_t> index;
    std::unordered_map<int, const PairedSample*> sample_of_point;  // board point -> its sample
  };
  std::map<int, FrameSamples> by_frame;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const PairedSample& s = samples[i];
    if (s.board_point < 0) continue;  // board-plane pixels are no fixed board point
    FrameSamples& f = by_frame[s.frame];
    f.time_s = s.time_s;
    f.index.push_back(i);
    f.sample_of_point[s.board_point] = &s;
  }
  std::vector<FrameSamples*> frames;
  std::vector<double> times;
  for (auto& [frame, f] : by_frame) frames.push_back(&f), times.push_back(f.time_s);
  const std::vector<bool> usable(frames.size(), true);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto pair = RatePair(times, usable, i, options.max_gap_s);
    if (!pair) continue;
    const auto [a, b] = *pair;
    const double dt = frames[b]->time_s - frames[a]->time_s;
    // rate = c0 + c1 du + c2 dv, du and dv in hundreds of pixels from the image centre.
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    int points = 0;
    for (std::size_t k : frames[i]->index) {
      const auto before = frames[a]->sample_of_point.find(samples[k].board_point);
      const auto after = frames[b]->sample_of_point.find(samples[k].board_point);
      if (before == frames[a]->sample_of_point.end() || after == frames[b]->sample_of_point.end()) continue;
      const Eigen::Vector3d row(1, (samples[k].u - 320) / 100, (samples[k].v - 240) / 100);
      normal += row * row.transpose();
      rhs += row * PointRate(*before->second, *after->second, dt, options.at_fixed_pixel);
      ++points;
    }
    if (points < options.min_points) continue;
    const Eigen::Vector3d c = normal.ldlt().solve(rhs);
    if (!c.allFinite()) continue;  // the points lie on a line: no plane
    for (std::size_t k : frames[i]->index)
      samples[k].raw_rate = c(0) + c(1) * (samples[k].u - 320) / 100 + c(2) * (samples[k].v - 240) / 100;
  }
  return samples;
}

bool RawRateOptions::IsValid(std::string* why) const {
  return OptionCheck(why).Positive(max_gap_s, "max_gap_s").AtLeast(min_points, 3, "min_points").valid();
}

}  // namespace speckle
