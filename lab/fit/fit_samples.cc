#include "lab/fit/fit_samples.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace speckle {

model::Covariates CovariatesOf(const PairedSample& s) {
  // Named, so a field out of order fails to compile instead of reading another.
  return {.raw = s.raw,
          .u = s.u,
          .v = s.v,
          .x = s.x,
          .y = s.y,
          .time_s = s.time_s,
          .tilt_deg = s.tilt_deg,
          .gradient_u = s.gradient_u,
          .gradient_v = s.gradient_v,
          .velocity_u = s.velocity_u,
          .velocity_v = s.velocity_v,
          .albedo = s.albedo,
          .raw_rate = s.raw_rate};
}

model::Covariates FitCovariatesOf(const PairedSample& s) {
  model::Covariates c = CovariatesOf(s);
  if (std::isfinite(s.fit_raw)) c.raw = s.fit_raw;
  return c;
}

std::size_t EvenStride(std::size_t count, std::size_t at_most) {
  return std::max<std::size_t>(1, (count + at_most - 1) / std::max<std::size_t>(1, at_most));
}

std::vector<int> FoldsByPose(const std::vector<PairedSample>& samples, int folds) {
  std::map<int, int> fold_of_pose;
  for (const auto& s : samples) fold_of_pose.emplace(s.pose, 0);
  int k = 0;
  for (auto& [pose, fold] : fold_of_pose) fold = folds > 0 ? k++ % folds : 0;
  std::vector<int> out;
  for (const auto& s : samples) out.push_back(fold_of_pose[s.pose]);
  return out;
}

namespace fitting {

double ReadingWeight(const DepthFitOptions& options, const PairedSample& s) {
  if (!options.millimetre_readings || !(s.raw > 0)) return 1;
  const double z_m = s.raw / 1000;
  return 1 / (z_m * z_m);
}

std::vector<const PairedSample*> Pointers(const std::vector<PairedSample>& samples) {
  std::vector<const PairedSample*> all;
  for (const auto& s : samples) all.push_back(&s);
  return all;
}

}  // namespace fitting
}  // namespace speckle
