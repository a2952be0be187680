#include "apps/calibration_comparison.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "apply/depth_corrector.h"
#include "schemas/errors.h"

namespace speckle {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A frame whose every pixel reads `raw`.
std::vector<std::uint16_t> UniformFrame(const apply::DepthCorrector& corrector, double raw) {
  return std::vector<std::uint16_t>(static_cast<std::size_t>(corrector.Width()) * corrector.Height(),
                                    static_cast<std::uint16_t>(std::lround(raw)));
}

// Every pixel's point (m, depth camera) under `corrector` when every pixel reads `raw`.
std::vector<float> UniformPoints(const apply::DepthCorrector& corrector, double raw) {
  return corrector.Cloud(UniformFrame(corrector, raw), 0).xyz;
}

double Median(std::vector<double> values) {
  if (values.empty()) return kNaN;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

double MedianDepth(const apply::DepthCorrector& corrector, double raw) {
  const std::vector<std::uint16_t> frame = UniformFrame(corrector, raw);
  std::vector<float> z(frame.size());
  corrector.Depth(frame, 0, z);
  std::vector<double> finite;
  for (float d : z)
    if (std::isfinite(d) && d > 0) finite.push_back(d);
  return Median(finite);
}

// The whole raw value whose median depth under `corrector` is nearest `depth_m`: the raw range sampled
// in 64 steps for the span where the model gives depths and the two samples around depth_m, then
// bisected between them (depth is monotonic in raw for every base form, rising or falling). NaN when
// no raw value gives that depth.
double RawForDepth(const apply::DepthCorrector& corrector, double depth_m, double raw_max) {
  const double step = std::ceil(raw_max / 64);
  double lo = kNaN, z_lo = kNaN;
  for (double raw = 1; raw <= raw_max; raw += step) {
    const double z = MedianDepth(corrector, raw);
    if (!std::isfinite(z)) continue;
    if (std::isfinite(z_lo) && (z_lo - depth_m) * (z - depth_m) <= 0) {
      double hi = raw, z_hi = z;
      const bool rising = z > z_lo;
      while (hi - lo > 1) {
        const double mid = std::floor((lo + hi) / 2), z_mid = MedianDepth(corrector, mid);
        if ((z_mid < depth_m) == rising)
          lo = mid, z_lo = z_mid;
        else
          hi = mid, z_hi = z_mid;
      }
      return std::abs(z_lo - depth_m) <= std::abs(z_hi - depth_m) ? lo : hi;
    }
    lo = raw, z_lo = z;
  }
  return kNaN;
}

double SigmaAt(const apply::DepthSigmaTable& table, double depth) {
  return table.depth_m.empty() ? kNaN : table.At(depth);
}

// A point's sigma under one calibration: its depth sigma, and sideways what
// its depth camera's focal length and principal point sigmas move a point at
// that pixel and depth (x = z (u - cx) / fx, first order).
double PointSigma(const ComparedCalibration& c, const float* xyz) {
  const double z = xyz[2], depth = SigmaAt(c.sigmas, z);
  const apply::PinholeCamera& k = c.calibration.depth;
  const auto& s = c.camera_sigma_px;
  const double sx = std::hypot(xyz[0] * s[0] / k.fx, z * s[2] / k.fx);
  const double sy = std::hypot(xyz[1] * s[1] / k.fy, z * s[3] / k.fy);
  return std::sqrt(depth * depth + sx * sx + sy * sy);
}

// The 3 x 3 cell with the largest mean ratio, in words.
std::string WorstRegion(const std::vector<float>& ratio, int width, int height) {
  static const char* kNames[3][3] = {
      {"top left", "top", "top right"}, {"left", "centre", "right"}, {"bottom left", "bottom", "bottom right"}};
  double sum[3][3] = {}, count[3][3] = {};
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      const float r = ratio[static_cast<std::size_t>(v) * width + u];
      if (!std::isfinite(r)) continue;
      sum[3 * v / height][3 * u / width] += r, count[3 * v / height][3 * u / width] += 1;
    }
  double worst = -1;
  std::string name = "none";
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (count[i][j] > 0 && sum[i][j] / count[i][j] > worst) worst = sum[i][j] / count[i][j], name = kNames[i][j];
  return name;
}

// The points' distance and its share beyond the sigmas, pixel by pixel.
void ComparePoints(const std::vector<float>& pa, const std::vector<float>& pb, const ComparedCalibration& ca,
                   const ComparedCalibration& cb, DepthComparison& out) {
  std::vector<double> depth_differences, distances;
  int beyond = 0;
  out.ratio.assign(pa.size() / 3, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t p = 0; p < out.ratio.size(); ++p) {
    const float *a = &pa[3 * p], *b = &pb[3 * p];
    if (!std::isfinite(a[2]) || !std::isfinite(b[2])) continue;
    const double distance = std::sqrt(std::pow(b[0] - a[0], 2) + std::pow(b[1] - a[1], 2) + std::pow(b[2] - a[2], 2));
    depth_differences.push_back(static_cast<double>(b[2]) - a[2]), distances.push_back(distance);
    if (distance > out.max_abs_difference_m)
      out.max_abs_difference_m = distance, out.max_u = static_cast<int>(p) % out.width,
      out.max_v = static_cast<int>(p) / out.width;
    const double sigma = PointSigma(ca, a) + PointSigma(cb, b);
    if (!std::isfinite(sigma)) continue;
    out.ratio[p] = static_cast<float>(distance / sigma);
    beyond += distance > sigma;
  }
  out.pixels = static_cast<int>(distances.size());
  if (out.pixels == 0) return;
  out.median_depth_difference_m = Median(depth_differences);
  std::sort(distances.begin(), distances.end());
  out.p95_abs_difference_m = distances[static_cast<std::size_t>(0.95 * static_cast<double>(distances.size() - 1))];
  out.share_beyond_sigma =
      std::isfinite(out.sigma_a_m + out.sigma_b_m) ? static_cast<double>(beyond) / out.pixels : kNaN;
  out.worst_region = out.max_abs_difference_m > 0 ? WorstRegion(out.ratio, out.width, out.height) : "nowhere";
}

DepthComparison AtDepth(const apply::DepthCorrector& a, const apply::DepthCorrector& b, const ComparedCalibration& ca,
                        const ComparedCalibration& cb, double depth_m, double raw_max) {
  DepthComparison out;
  out.depth_m = depth_m, out.width = a.Width(), out.height = a.Height();
  out.sigma_a_m = SigmaAt(ca.sigmas, depth_m), out.sigma_b_m = SigmaAt(cb.sigmas, depth_m);
  out.extrapolated = !ca.sigmas.Covers(depth_m) || !cb.sigmas.Covers(depth_m);
  out.raw = RawForDepth(a, depth_m, raw_max);
  if (!std::isfinite(out.raw)) return out;  // no pixel compared: A reads no raw value as this depth
  ComparePoints(UniformPoints(a, out.raw), UniformPoints(b, out.raw), ca, cb, out);
  return out;
}

}  // namespace

std::vector<DepthComparison> CompareCalibrations(const ComparedCalibration& a, const ComparedCalibration& b,
                                                 const ComparisonOptions& options) {
  const apply::PinholeCamera &da = a.calibration.depth, &db = b.calibration.depth;
  if (da.width != db.width || da.height != db.height)
    throw InputError(fmt::format("{} and {}: depth images of {}x{} and {}x{} cannot be compared pixel by pixel",
                                 a.calibration.file.string(), b.calibration.file.string(), da.width, da.height,
                                 db.width, db.height));
  if (a.calibration.depth_units != b.calibration.depth_units)
    throw InputError(fmt::format("{} and {}: one reads {} depth, the other {}", a.calibration.file.string(),
                                 b.calibration.file.string(), ToString(a.calibration.depth_units),
                                 ToString(b.calibration.depth_units)));
  const apply::DepthCorrector ca(a.calibration), cb(b.calibration);
  for (const auto* c : {&ca, &cb})
    if (const std::string note = apply::FoldNote(c->Summary()); !note.empty()) spdlog::info("{}", note);
  const double raw_max = a.calibration.depth_units == DepthUnits::kMillimetre ? 65535 : 2046;
  std::vector<DepthComparison> out;
  for (double depth : options.depths_m) out.push_back(AtDepth(ca, cb, a, b, depth, raw_max));
  return out;
}

}  // namespace speckle
