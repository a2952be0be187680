#include "apply/depth_corrector.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "apply/correction_kernel.h"
#include "model/depth_model.h"
#include "model/undistortion_grid.h"
#include "schemas/depth_reading.h"
#include "schemas/errors.h"

namespace speckle::apply {
namespace {

constexpr float kNoPoint = std::numeric_limits<float>::quiet_NaN();

// The raw value through the grid, then the model, at one pixel: the exact
// evaluation every table is checked against.
double ExactDepth(const DepthCalibration& calibration, model::Covariates c, double raw) {
  c.raw = calibration.grid ? calibration.grid->Apply(raw, c.x, c.y) : raw;
  return calibration.model->Depth(c);
}

model::Covariates PixelCovariates(const CorrectorOptions& options, int u, int v, double x, double y, double time_s) {
  model::Covariates c = options.still_scene;
  c.u = u, c.v = v, c.x = x, c.y = y, c.time_s = time_s;
  return c;
}

// The pipeline's rule (schemas/depth_reading.h): 0 is no reading in either
// unit; so are 2047 and above in 11-bit raw values.
bool IsReading(std::uint16_t raw, DepthUnits units) { return DepthReading(units).IsReading(raw); }

// The tables' largest error against the model over the checked pixels, three
// points inside every span of `knots` knots `step` apart from s.raw_lo, and
// where it is.
template <class Corrected>
void FoldError(const Corrected& corrected, const std::vector<std::size_t>& checked, int width, double step, int knots,
               FoldSummary& s) {
  s.max_error_raw = 0, s.worst_u = -1, s.worst_v = -1, s.worst_raw = 0;
  for (std::size_t p : checked) {
    double previous = corrected(p, s.raw_lo);
    for (int k = 1; k < knots; ++k) {
      const double next = corrected(p, s.raw_lo + k * step);
      for (double t : {0.25, 0.5, 0.75}) {
        const double raw = s.raw_lo + (k - 1 + t) * step;
        const double error = std::abs(corrected(p, raw) - (previous + t * (next - previous)));
        if (error <= s.max_error_raw) continue;
        s.max_error_raw = error;
        s.worst_u = static_cast<int>(p % width), s.worst_v = static_cast<int>(p / width), s.worst_raw = raw;
      }
      previous = next;
    }
  }
}

}  // namespace

DepthCorrector::DepthCorrector(const DepthCalibration& calibration, const CorrectorOptions& options)
    : calibration_(calibration), options_(options), width_(calibration.depth.width), height_(calibration.depth.height) {
  const model::DepthModel& m = *calibration.model;
  const std::size_t n = static_cast<std::size_t>(width_) * height_;
  ray_x_.resize(n), ray_y_.resize(n);
  for (int v = 0; v < height_; ++v) {
    for (int u = 0; u < width_; ++u) {
      const Eigen::Vector2d ray = calibration.depth.Ray(u, v);
      ray_x_[v * width_ + u] = static_cast<float>(ray.x());
      ray_y_[v * width_ + u] = static_cast<float>(ray.y());
    }
  }
  // Which effects fold into the tables: those that do not change from frame to frame.
  static const std::set<std::string> kPixelAndRaw{"raw", "u", "v", "x", "y"};
  std::vector<std::size_t> folded;
  for (std::size_t k = 0; k < m.Effects().size(); ++k) {
    const auto reads = m.Effects()[k]->CovariatesRead();
    const bool time = std::count(reads.begin(), reads.end(), "time_s") > 0;
    const bool pixel =
        std::any_of(reads.begin(), reads.end(), [](const std::string& r) { return kPixelAndRaw.count(r) > 0; });
    auto& group = !time ? folded : pixel ? per_pixel_ : per_frame_;
    auto& names = !time ? summary_.folded : pixel ? summary_.per_pixel : summary_.per_frame;
    group.push_back(k);
    names.push_back(m.Effects()[k]->Name());
  }
  // The corrected raw value at pixel p: through the grid, less the folded effects.
  const auto corrected = [&](std::size_t p, double raw) {
    model::Covariates c =
        PixelCovariates(options_, static_cast<int>(p % width_), static_cast<int>(p / width_), ray_x_[p], ray_y_[p], 0);
    c.raw = calibration.grid ? calibration.grid->Apply(raw, c.x, c.y) : raw;
    double value = c.raw;
    for (std::size_t k : folded) value -= m.Effects()[k]->RawOffset(m.EffectParameters(k).data(), c);
    return value;
  };
  // Tabulate over the raw values of the depth range, with a margin.
  const double* base = m.Base().data();
  const double r_near = model::RawFromDepth(m.Definition().form, base, options.min_depth_m);
  const double r_far = model::RawFromDepth(m.Definition().form, base, options.max_depth_m);
  if (!std::isfinite(r_near) || !std::isfinite(r_far))
    throw InputError(calibration.file.string() + ": model.parameters: the depth range " +
                     std::to_string(options.min_depth_m) + " to " + std::to_string(options.max_depth_m) +
                     " m has no finite raw values");
  const double margin = 0.05 * std::abs(r_far - r_near) + 5;
  const double lo = std::max(0.0, std::min(r_near, r_far) - margin), hi = std::max(r_near, r_far) + margin;
  // The grid is linear in raw between its nodes: with knots on them it folds
  // exactly, so knots start at the grid's node spacing (else one span).
  double step = hi - lo, anchor = lo;
  if (calibration.grid && calibration.grid->raw_nodes.size() >= 2) {
    const auto& nodes = calibration.grid->raw_nodes;
    step = (nodes.back() - nodes.front()) / static_cast<double>(nodes.size() - 1);
    anchor = nodes.front();
  }
  // Knots beyond options.max_knots are never tabulated (the grid's nodes are
  // at least a raw unit apart; see UndistortionGrid::Problem).
  step = std::max(step, (hi - lo) / options.max_knots);
  std::vector<std::size_t> checked;
  for (int v = 4; v < height_; v += 8)
    for (int u = 4; u < width_; u += 8)
      if (std::isfinite(ray_x_[v * width_ + u])) checked.push_back(static_cast<std::size_t>(v) * width_ + u);
  // Knots halve their spacing (nested) until the tables meet the tolerance on
  // every 8th pixel along both axes, three points inside every span.
  int knots = 0;
  for (;; step /= 2) {
    summary_.raw_lo = anchor - std::ceil((anchor - lo) / step) * step;
    knots = static_cast<int>(std::ceil((hi - summary_.raw_lo) / step)) + 1;
    FoldError(corrected, checked, width_, step, knots, summary_);
    if (summary_.max_error_raw <= options.fold_tolerance_raw || 2 * knots - 1 > options.max_knots) break;
  }
  // Tables that cannot meet the tolerance (an effect sharper in raw than
  // max_knots can follow: a per-pixel pattern's decay missed by 1.12 raw on
  // Herrera's set) are not used: every pixel is evaluated exactly, as for
  // effects of time and pixel, and the summary says why.
  summary_.exact = summary_.max_error_raw > options.fold_tolerance_raw;
  summary_.knots = knots;
  summary_.raw_hi = summary_.raw_lo + (knots - 1) * step;
  raw_lo_ = static_cast<float>(summary_.raw_lo);
  knot_step_ = static_cast<float>(step);
  if (summary_.exact) return;
  table_.resize(static_cast<std::size_t>(knots) * n);
  for (int k = 0; k < knots; ++k)
    for (std::size_t p = 0; p < n; ++p)  // NaN where the pixel has no ray: no point, at no cost per frame
      table_[k * n + p] =
          std::isfinite(ray_x_[p]) ? static_cast<float>(corrected(p, summary_.raw_lo + k * step)) : kNoPoint;
}

double DepthCorrector::FrameOffset(double time_s) const {
  const model::DepthModel& m = *calibration_.model;
  model::Covariates c = options_.still_scene;
  c.time_s = time_s;
  double offset = 0;
  for (std::size_t k : per_frame_) offset += m.Effects()[k]->RawOffset(m.EffectParameters(k).data(), c);
  return offset;
}

void DepthCorrector::CheckSize(std::size_t size, int channels, const char* what) const {
  const std::size_t expected = static_cast<std::size_t>(width_) * height_ * channels;
  if (size != expected) {
    throw InputError(fmt::format("{} has {} values, expected {} for the calibration's {} x {} depth image{}", what,
                                 size, expected, width_, height_,
                                 channels > 1 ? fmt::format(" ({} per pixel)", channels) : ""));
  }
}

void DepthCorrector::Apply(std::span<const std::uint16_t> raw, double time_s, float* xyz, float* depth) const {
  CheckSize(raw.size(), 1, "the depth frame");
  if (!per_pixel_.empty() || summary_.exact) {  // effects of time and pixel, or tables out of tolerance
    std::vector<float> exact(xyz ? 0 : 3 * raw.size());
    const std::span<float> cloud = xyz ? std::span<float>(xyz, 3 * raw.size()) : std::span<float>(exact);
    NaivePointCloud(calibration_, options_, raw, time_s, cloud);
    if (depth)
      for (std::size_t p = 0; p < raw.size(); ++p) depth[p] = cloud[3 * p + 2];
    return;
  }
  KernelInput in;
  in.raw = raw.data();
  in.pixels = static_cast<int>(raw.size());
  in.table = table_.data();
  in.ray_x = ray_x_.data(), in.ray_y = ray_y_.data();
  in.raw_lo = raw_lo_, in.inverse_step = 1 / knot_step_;
  in.last_span = summary_.knots - 2;
  in.frame_offset = static_cast<float>(FrameOffset(time_s));
  in.near = static_cast<float>(options_.min_depth_m), in.far = static_cast<float>(options_.max_depth_m);
  in.no_reading_from = calibration_.depth_units == DepthUnits::kRaw11Bit ? 2047 : 1 << 16;
  in.form = calibration_.model->Definition().form;
  const std::vector<double>& base = calibration_.model->Base();
  std::transform(base.begin(), base.end(), in.base, [](double p) { return static_cast<float>(p); });
  CorrectFrame(in, xyz, depth);
}

void DepthCorrector::PointCloud(std::span<const std::uint16_t> raw, double time_s, std::span<float> xyz) const {
  CheckSize(xyz.size(), 3, "the point cloud");
  Apply(raw, time_s, xyz.data(), nullptr);
}

void DepthCorrector::Depth(std::span<const std::uint16_t> raw, double time_s, std::span<float> depth_m) const {
  CheckSize(depth_m.size(), 1, "the depth image");
  Apply(raw, time_s, nullptr, depth_m.data());
}

void DepthCorrector::RegisterColour(std::span<const float> xyz, std::span<const std::uint8_t> rgb,
                                    std::span<std::uint8_t> out) const {
  CheckSize(xyz.size(), 3, "the point cloud");
  CheckSize(out.size(), 3, "the colour output");
  const PinholeCamera& colour = calibration_.colour;
  const std::size_t colour_values = static_cast<std::size_t>(colour.width) * colour.height * 3;
  if (rgb.size() != colour_values) {
    throw InputError(fmt::format("the colour frame has {} values, expected {} for the calibration's {} x {} RGB image",
                                 rgb.size(), colour_values, colour.width, colour.height));
  }
  ColourCamera camera{};
  const Eigen::Isometry3d colour_from_depth = calibration_.depth_from_colour.inverse();
  for (int i = 0; i < 9; ++i) camera.rotation[i] = static_cast<float>(colour_from_depth.linear()(i / 3, i % 3));
  for (int i = 0; i < 3; ++i) camera.translation[i] = static_cast<float>(colour_from_depth.translation()[i]);
  camera.fx = static_cast<float>(colour.fx), camera.fy = static_cast<float>(colour.fy);
  camera.cx = static_cast<float>(colour.cx), camera.cy = static_cast<float>(colour.cy);
  for (int i = 0; i < 5; ++i) camera.distortion[i] = static_cast<float>(colour.distortion[i]);
  camera.width = colour.width, camera.height = colour.height;
  const int points = static_cast<int>(xyz.size() / 3);
  std::vector<int> pixel(points);
  ColourPixels(camera, xyz.data(), points, pixel.data());
  for (int p = 0; p < points; ++p) {
    if (pixel[p] < 0) {
      std::fill_n(&out[3 * p], 3, 0);
    } else {
      std::copy_n(&rgb[3 * static_cast<std::size_t>(pixel[p])], 3, &out[3 * p]);
    }
  }
}

OrganizedCloud DepthCorrector::Cloud(std::span<const std::uint16_t> raw, double time_s,
                                     std::span<const std::uint8_t> rgb) const {
  OrganizedCloud cloud{width_, height_, std::vector<float>(3 * raw.size()), {}};
  PointCloud(raw, time_s, cloud.xyz);
  if (!rgb.empty()) {
    cloud.rgb.resize(cloud.xyz.size());
    RegisterColour(cloud.xyz, rgb, cloud.rgb);
  }
  return cloud;
}

void NaivePointCloud(const DepthCalibration& calibration, const CorrectorOptions& options,
                     std::span<const std::uint16_t> raw, double time_s, std::span<float> xyz) {
  const PinholeCamera& camera = calibration.depth;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const std::size_t p = static_cast<std::size_t>(v) * camera.width + u;
      const Eigen::Vector2d ray = camera.Ray(u, v);
      double z = ExactDepth(calibration, PixelCovariates(options, u, v, ray.x(), ray.y(), time_s), raw[p]);
      if (!(IsReading(raw[p], calibration.depth_units) && std::isfinite(ray.x()) && z >= options.min_depth_m &&
            z <= options.max_depth_m))
        z = kNoPoint;
      xyz[3 * p] = static_cast<float>(z * ray.x());
      xyz[3 * p + 1] = static_cast<float>(z * ray.y());
      xyz[3 * p + 2] = static_cast<float>(z);
    }
  }
}

std::string FoldNote(const FoldSummary& s, const CorrectorOptions& options) {
  if (!s.exact) return "";
  return fmt::format(
      "the model does not fold into per-pixel tables within {} raw ({} knots miss it by up to {:.3f} raw, at pixel "
      "({}, {}) and raw {:.0f}): every pixel is evaluated exactly instead, slower but without that error",
      options.fold_tolerance_raw, s.knots, s.max_error_raw, s.worst_u, s.worst_v, s.worst_raw);
}

}  // namespace speckle::apply
