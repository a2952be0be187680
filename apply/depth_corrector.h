#pragma once
// Raw depth frames to metric depth and organized point clouds the thesis's
// high-fidelity way (appendix D.3.1): no resampling. Every pixel keeps its
// place and its ray comes from its own distorted position, computed once.
// The undistortion grid and the effects that depend only on the pixel and
// the raw value are folded into per-pixel tables of the corrected raw value
// at a few raw knots (linear in between, checked against the exact model
// when built); effects of time add one offset per frame; the base form is
// evaluated in closed form.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "apply/depth_calibration.h"
#include "model/covariates.h"

namespace speckle::apply {

struct CorrectorOptions {
  // Covariates one frame of a still scene does not give: its raw rate and
  // velocities are 0, and an unknown surface is taken as the board corners'
  // albedo, 0.5.
  model::Covariates still_scene;
  double min_depth_m = 0.4, max_depth_m = 10.0;  // outside: no point; also the raw range tabulated
  double fold_tolerance_raw = 0.01;              // the tables' largest error against the model
  int max_knots = 129;
};

// How the model was folded, for the user and the tests.
struct FoldSummary {
  int knots = 0;  // raw knots of the per-pixel tables (2: affine in raw)
  double raw_lo = 0, raw_hi = 0;
  double max_error_raw = 0;        // the tables' largest error against the model at the checked points
  int worst_u = -1, worst_v = -1;  // where it is, and at which raw value
  double worst_raw = 0;
  bool exact = false;                  // over the tolerance: tables unused, every pixel evaluated exactly
  std::vector<std::string> folded;     // effects in the tables
  std::vector<std::string> per_frame;  // effects of time only: one offset per frame
  std::vector<std::string> per_pixel;  // effects evaluated exactly at every pixel (time and pixel)
};

// Said when the tables miss their tolerance and every pixel is evaluated
// exactly instead (slower); empty otherwise.
std::string FoldNote(const FoldSummary& s, const CorrectorOptions& options = {});

struct OrganizedCloud {
  int width = 0, height = 0;
  std::vector<float> xyz;         // 3 per pixel, row-major, metres, depth camera; NaN where no point
  std::vector<std::uint8_t> rgb;  // 3 per pixel when colour was registered, else empty
};

class DepthCorrector {
 public:
  explicit DepthCorrector(const DepthCalibration& calibration, const CorrectorOptions& options = {});

  int Width() const { return width_; }
  int Height() const { return height_; }
  const FoldSummary& Summary() const { return summary_; }
  const DepthCalibration& Calibration() const { return calibration_; }

  // `raw`: Width() x Height() values in the calibration's depth units (2047
  // or more, or 0 for millimetres: no reading). `time_s`: since the sensor's
  // warm-up began, as the calibration's session counted it (its first frame:
  // recorder/recording_clock.h) (thermal drift). Throws InputError when a size is wrong.
  void PointCloud(std::span<const std::uint16_t> raw, double time_s, std::span<float> xyz) const;
  // Depth along the optical axis per pixel (NaN: no reading), unresampled.
  void Depth(std::span<const std::uint16_t> raw, double time_s, std::span<float> depth_m) const;
  // Each point's colour from an RGB image of the colour camera (nearest
  // pixel; black where the point falls outside it). Occlusion between the
  // cameras is not modelled: a point hidden from the colour camera takes its
  // occluder's colour.
  void RegisterColour(std::span<const float> xyz, std::span<const std::uint8_t> rgb, std::span<std::uint8_t> out) const;
  OrganizedCloud Cloud(std::span<const std::uint16_t> raw, double time_s, std::span<const std::uint8_t> rgb = {}) const;

 private:
  // Either output may be null.
  void Apply(std::span<const std::uint16_t> raw, double time_s, float* xyz, float* depth) const;
  double FrameOffset(double time_s) const;
  void CheckSize(std::size_t size, int channels, const char* what) const;

  DepthCalibration calibration_;
  CorrectorOptions options_;
  int width_ = 0, height_ = 0;
  std::vector<float> ray_x_, ray_y_;  // per pixel; NaN where the lens model has no inverse
  std::vector<float> table_;          // [knot][pixel]: corrected raw value at the knot (NaN: no ray)
  float raw_lo_ = 0, knot_step_ = 1;
  std::vector<std::size_t> per_frame_, per_pixel_;  // effect indices
  FoldSummary summary_;
};

// The reference: the generic model evaluated at every pixel, undistorting
// its ray on the way (what DepthCorrector must agree with, and the naive
// baseline of the benchmark).
void NaivePointCloud(const DepthCalibration& calibration, const CorrectorOptions& options,
                     std::span<const std::uint16_t> raw, double time_s, std::span<float> xyz);

}  // namespace speckle::apply
