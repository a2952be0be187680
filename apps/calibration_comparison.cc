#include "apps/calibration_comparison.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

#include "apply/depth_corrector.h"
#include "apps/model_sigma_shape.h"
#include "schemas/errors.h"
#include "stages/lens_autodiff.h"

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

// Per pixel, the sigmas of its ray's x/z and y/z under the depth camera's
// covariance: the ray's derivatives by the camera's nine terms (the lens
// autodiff the fits use), moved through the covariance. Two floats a pixel;
// NaN where the lens model does not invert.
std::vector<float> RaySigmas(const ComparedCalibration& c) {
  using Jet = ceres::Jet<double, 9>;
  const apply::PinholeCamera& cam = c.calibration.depth;
  Jet k[4] = {Jet(cam.fx, 0), Jet(cam.fy, 1), Jet(cam.cx, 2), Jet(cam.cy, 3)}, lens[5];
  for (int i = 0; i < 5; ++i) lens[i] = Jet(cam.distortion[static_cast<std::size_t>(i)], 4 + i);
  const Eigen::Map<const Eigen::Matrix<double, 9, 9, Eigen::RowMajor>> covariance(c.camera_covariance.data());
  std::vector<float> out(2 * static_cast<std::size_t>(cam.width) * cam.height, std::numeric_limits<float>::quiet_NaN());
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      Jet ray[2];
      Undistort(k, lens, u, v, ray);
      if (!std::isfinite(ray[0].a) || !std::isfinite(ray[1].a)) continue;
      const std::size_t p = static_cast<std::size_t>(v) * cam.width + u;
      out[2 * p] = static_cast<float>(std::sqrt(std::max(0.0, ray[0].v.dot(covariance * ray[0].v))));
      out[2 * p + 1] = static_cast<float>(std::sqrt(std::max(0.0, ray[1].v.dot(covariance * ray[1].v))));
    }
  return out;
}

// One calibration as compared: its stated sigmas, and its rays' sigmas per pixel.
struct Compared {
  const ComparedCalibration& calibration;
  std::vector<float> ray_sigmas;
};

// A point's sigma under one calibration: its depth sigma (the report's at
// that depth, shaped over the image by its model's covariance), and sideways what
// its depth camera's covariance moves the point at that pixel and depth.
double PointSigma(const Compared& c, const ModelSigmaShape& shape, std::size_t pixel, int width, const float* xyz) {
  const double z = xyz[2];
  const double depth = SigmaAt(c.calibration.sigmas, z) *
                       shape.At(static_cast<double>(pixel % width), static_cast<double>(pixel / width));
  const double sx = z * c.ray_sigmas[2 * pixel], sy = z * c.ray_sigmas[2 * pixel + 1];
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

// The points' distance and its shares beyond the sigmas, pixel by pixel.
void ComparePoints(const std::vector<float>& pa, const std::vector<float>& pb, const Compared& ca, const Compared& cb,
                   const ModelSigmaShape& sa, const ModelSigmaShape& sb, double differ_sigmas, DepthComparison& out) {
  std::vector<double> depth_differences, distances;
  int beyond = 0, differing = 0;
  out.ratio.assign(pa.size() / 3, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t p = 0; p < out.ratio.size(); ++p) {
    const float *a = &pa[3 * p], *b = &pb[3 * p];
    if (!std::isfinite(a[2]) || !std::isfinite(b[2])) continue;
    const double distance = std::sqrt(std::pow(b[0] - a[0], 2) + std::pow(b[1] - a[1], 2) + std::pow(b[2] - a[2], 2));
    depth_differences.push_back(static_cast<double>(b[2]) - a[2]), distances.push_back(distance);
    if (distance > out.max_abs_difference_m)
      out.max_abs_difference_m = distance, out.max_u = static_cast<int>(p) % out.width,
      out.max_v = static_cast<int>(p) / out.width;
    const double sigma_a = PointSigma(ca, sa, p, out.width, a), sigma_b = PointSigma(cb, sb, p, out.width, b);
    if (!std::isfinite(sigma_a + sigma_b)) continue;
    out.ratio[p] = static_cast<float>(distance / (sigma_a + sigma_b));
    beyond += distance > sigma_a + sigma_b;
    differing += distance > differ_sigmas * std::hypot(sigma_a, sigma_b);
  }
  out.pixels = static_cast<int>(distances.size());
  if (out.pixels == 0) return;
  out.median_depth_difference_m = Median(depth_differences);
  std::sort(distances.begin(), distances.end());
  out.p95_abs_difference_m = distances[static_cast<std::size_t>(0.95 * static_cast<double>(distances.size() - 1))];
  const bool judged = std::isfinite(out.sigma_a_m + out.sigma_b_m);
  out.share_beyond_sigma = judged ? static_cast<double>(beyond) / out.pixels : kNaN;
  out.share_differing = judged ? static_cast<double>(differing) / out.pixels : kNaN;
  out.worst_region = out.max_abs_difference_m > 0 ? WorstRegion(out.ratio, out.width, out.height) : "nowhere";
}

DepthComparison AtDepth(const apply::DepthCorrector& a, const apply::DepthCorrector& b, const Compared& ca,
                        const Compared& cb, double depth_m, double raw_max, double differ_sigmas) {
  DepthComparison out;
  out.depth_m = depth_m, out.width = a.Width(), out.height = a.Height();
  const apply::DepthSigmaTable &sa = ca.calibration.sigmas, &sb = cb.calibration.sigmas;
  out.sigma_a_m = SigmaAt(sa, depth_m), out.sigma_b_m = SigmaAt(sb, depth_m);
  out.extrapolated = !sa.Covers(depth_m) || !sb.Covers(depth_m);
  out.raw = RawForDepth(a, depth_m, raw_max);
  if (!std::isfinite(out.raw)) return out;  // no pixel compared: A reads no raw value as this depth
  // The report's sigma is the image centre's; each model's covariance says how it varies over the image.
  const auto shape = [&](const Compared& c) {
    return ModelSigmaShapeAt(c.calibration.calibration, c.calibration.model_covariance, out.raw);
  };
  ComparePoints(UniformPoints(a, out.raw), UniformPoints(b, out.raw), ca, cb, shape(ca), shape(cb), differ_sigmas, out);
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
  const Compared ra{a, RaySigmas(a)}, rb{b, RaySigmas(b)};
  std::vector<DepthComparison> out;
  for (double depth : options.depths_m) out.push_back(AtDepth(ca, cb, ra, rb, depth, raw_max, options.differ_sigmas));
  return out;
}

}  // namespace speckle
