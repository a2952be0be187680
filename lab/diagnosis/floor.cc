#include "lab/diagnosis/floor.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

namespace speckle {
namespace {

// The grid's part: its correction was estimated from walls with noise of
// their own, and every undistorted sample carries that error, which no depth
// model removes and which consecutive frames of a board point share. In
// wide-angle rooms (0.2 raw floors) it was about 0.1 raw.
double GridPart(const std::vector<double>& grid_std_error_raw, const std::vector<double>& residual) {
  double squares = 0;
  int count = 0;
  for (std::size_t i = 0; i < grid_std_error_raw.size() && i < residual.size(); ++i)
    if (std::isfinite(residual[i])) squares += grid_std_error_raw[i] * grid_std_error_raw[i], ++count;
  return count > 0 ? std::sqrt(squares / count) : -1;
}

// Neighbouring pixels of one frame (board-plane pixels): a smooth model
// error cancels in their difference; spatially correlated noise partly does
// too, so this floor is a lower bound. -1 with fewer than 100 pairs.
double NeighbourPixelsFloor(const std::vector<PairedSample>& samples, const std::vector<double>& residual) {
  std::map<std::tuple<int, int, int>, double> by_pixel;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (samples[i].point != SamplePoint::kBoardPlanePixel) continue;
    by_pixel[{samples[i].frame, static_cast<int>(std::lround(samples[i].v)),
              static_cast<int>(std::lround(samples[i].u))}] = residual[i];
  }
  double pair_squares = 0;
  int pairs = 0;
  // Board-plane pixels may be a sparse subset: the next one along the row within 3 pixels.
  for (auto it = by_pixel.begin(); it != by_pixel.end(); ++it) {
    const auto next = std::next(it);
    if (next == by_pixel.end()) break;
    const auto [frame, v, u] = it->first;
    const auto [next_frame, next_v, next_u] = next->first;
    if (next_frame == frame && next_v == v && next_u - u <= 3)
      pair_squares += (it->second - next->second) * (it->second - next->second), ++pairs;
  }
  return pairs >= 100 ? std::sqrt(pair_squares / pairs / 2) : -1;
}

// Neighbouring interior corners of one frame (sessions of one frame a pose):
// each corner and its nearest corner at least options.min_neighbour_corner_px
// away, so their raw windows share no pixel. A smooth model error and the
// frame's colour pose error nearly cancel in their difference; noise
// correlated between the windows partly does too, so, like the pixels', this
// floor is a lower bound. Corners, not square centres: neighbouring centres
// show opposite albedos. -1 with fewer than 100 pairs.
double NeighbourCornersFloor(const DiagnosisOptions& options, const std::vector<PairedSample>& samples,
                             const std::vector<double>& residual) {
  std::map<int, std::vector<std::size_t>> by_frame;
  for (std::size_t i = 0; i < samples.size(); ++i)
    if (samples[i].point == SamplePoint::kInteriorCorner && std::isfinite(residual[i]))
      by_frame[samples[i].frame].push_back(i);
  std::set<std::pair<std::size_t, std::size_t>> pairs;
  for (const auto& [frame, corners] : by_frame) {
    for (std::size_t a : corners) {
      std::size_t nearest = a;
      double best = options.max_neighbour_corner_px;
      for (std::size_t b : corners) {
        const double d = std::hypot(samples[a].u - samples[b].u, samples[a].v - samples[b].v);
        if (d >= options.min_neighbour_corner_px && d <= best) best = d, nearest = b;
      }
      if (nearest != a) pairs.insert(std::minmax(a, nearest));
    }
  }
  if (pairs.size() < 100) return -1;
  double squares = 0;
  for (const auto& [a, b] : pairs) squares += std::pow(residual[a] - residual[b], 2);
  return std::sqrt(squares / static_cast<double>(pairs.size()) / 2);
}

}  // namespace

// The truth's part: every frame of a pose shares its colour pose's error,
// which no depth model can remove; its size follows from the corners'
// reprojection scatter (truth_sigma_m), converted to raw units by the
// fitted model's slope.
double TruthPartRaw(const model::DepthModel& model, const std::vector<PairedSample>& samples) {
  double truth_squares = 0;
  int truths = 0;
  for (const auto& s : samples) {
    if (!std::isfinite(s.truth_sigma_m)) continue;
    model::Covariates c = CovariatesOf(s);
    c.raw = s.raw + 0.5;
    const double far = model.Depth(c);
    c.raw = s.raw - 0.5;
    const double slope = std::abs(far - model.Depth(c));  // metres per raw unit
    if (!(slope > 0) || !std::isfinite(slope)) continue;
    truth_squares += std::pow(s.truth_sigma_m / slope, 2);
    ++truths;
  }
  return truths > 0 ? std::sqrt(truth_squares / truths) : -1;
}

void SumFloorParts(NoiseFloor& floor) {
  const double sensor = floor.sensor_raw;
  const double truth = std::hypot(std::max(0.0, floor.colour_pose_raw), std::max(0.0, floor.cameras_raw));
  floor.floor_raw = std::hypot(sensor, truth, std::max(0.0, floor.grid_raw));
  floor.beyond_cameras_raw = std::hypot(sensor, std::max(0.0, floor.colour_pose_raw), std::max(0.0, floor.grid_raw));
}

NoiseFloor EstimateFloor(const DiagnosisOptions& options, const std::vector<PairedSample>& samples, const DepthFit& fit,
                         const std::vector<double>& grid_std_error_raw) {
  const std::vector<double>& residual = fit.residual_raw;
  const model::DepthModel model = fit.Model();
  NoiseFloor floor;
  floor.quantization_raw = 1 / std::sqrt(12.0);
  // The same board point in consecutive frames: what differs is noise (raw
  // value and colour pose), never the model, whose error at a still board's
  // pixel is the same and at a drifting board's pixel a few pixels away
  // nearly so. Var(difference) = 2 sigma^2.
  std::map<std::pair<int, int>, std::pair<double, double>> by_point;  // (board point, frame) -> (time, residual)
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (samples[i].board_point >= 0 && std::isfinite(residual[i]))
      by_point[{samples[i].board_point, samples[i].frame}] = {samples[i].time_s, residual[i]};
  }
  double squares = 0;
  std::set<int> frames;
  for (const auto& [key, value] : by_point) {
    const auto next = by_point.find({key.first, key.second + 1});
    if (next == by_point.end() || next->second.first - value.first > options.max_consecutive_gap_s) continue;
    squares += std::pow(next->second.second - value.second, 2);
    ++floor.consecutive_pairs;
    frames.insert(key.second);
  }
  if (static_cast<int>(frames.size()) >= options.min_consecutive_frames)
    floor.consecutive_frames_raw = std::sqrt(squares / floor.consecutive_pairs / 2);
  floor.neighbour_pixels_raw = NeighbourPixelsFloor(samples, residual);
  floor.neighbour_corners_raw = NeighbourCornersFloor(options, samples, residual);
  // The sensor's part: frame-to-frame noise where there are consecutive
  // frames, else pixel-to-pixel, else corner-to-corner, else rounding.
  double sensor = floor.quantization_raw;
  std::string source = "quantization only (no consecutive frames of a board)";
  if (floor.consecutive_frames_raw > 0) {
    sensor = floor.consecutive_frames_raw;
    source = "the same board points in consecutive frames";
  } else if (floor.neighbour_pixels_raw > 0) {
    sensor = floor.neighbour_pixels_raw;
    source = "neighbouring pixels of each frame";
  } else if (floor.neighbour_corners_raw > 0) {
    sensor = floor.neighbour_corners_raw;
    source = "neighbouring corners of each frame";
  }
  floor.colour_pose_raw = TruthPartRaw(model, samples);
  // The cameras' part: the intrinsics and extrinsics that turned the colour
  // poses into true depths are uncertain too, and a one-sigma error of each
  // leaves residuals the refitted model cannot remove (the fit measured how
  // much, per camera input).
  if (!fit.camera_raw_rms.empty()) {
    double squares_cameras = 0;
    for (double r : fit.camera_raw_rms) squares_cameras += r * r;
    floor.cameras_raw = std::sqrt(squares_cameras);
  }
  floor.sensor_raw = sensor;
  floor.grid_raw = GridPart(grid_std_error_raw, residual);
  SumFloorParts(floor);
  if (floor.colour_pose_raw > 0 && floor.cameras_raw > 0)
    source += ", with the colour poses' and the cameras' uncertainty";
  else if (floor.colour_pose_raw > 0)
    source += ", with the colour poses' uncertainty";
  else if (floor.cameras_raw > 0)
    source += ", with the cameras' uncertainty";
  if (floor.grid_raw > 0) source += ", and the undistortion grid's standard error";
  floor.source = source;
  return floor;
}

}  // namespace speckle
