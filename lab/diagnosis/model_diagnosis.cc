#include "lab/diagnosis/model_diagnosis.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <set>

#include "lab/diagnosis/verdict.h"
#include "lab/stats/pose_tests.h"
#include "model/effect.h"
#include "stages/significant_digits.h"
#include "stages/step_clock.h"

namespace speckle {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

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
  // The truth's part: every frame of a pose shares its colour pose's error,
  // which no depth model can remove; its size follows from the corners'
  // reprojection scatter (truth_sigma_m), converted to raw units by the
  // fitted model's slope.
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
  if (truths > 0) floor.colour_pose_raw = std::sqrt(truth_squares / truths);
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
  const double truth = std::hypot(std::max(0.0, floor.colour_pose_raw), std::max(0.0, floor.cameras_raw));
  floor.floor_raw = std::hypot(sensor, truth, std::max(0.0, floor.grid_raw));
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

struct CovariateAxis {
  const char* name;
  const char* unit;
  std::function<double(const PairedSample&)> value;
  std::function<double(const PairedSample&)> second;  // set for 2-D axes
};

const std::vector<CovariateAxis>& Axes() {
  static const std::vector<CovariateAxis> axes = {
      {"raw", "raw", [](const PairedSample& s) { return s.raw; }, nullptr},
      {"depth", "m", [](const PairedSample& s) { return s.depth_m; }, nullptr},
      {"image radius", "1", [](const PairedSample& s) { return std::hypot(s.x, s.y); }, nullptr},
      {"image x", "1", [](const PairedSample& s) { return s.x; }, nullptr},
      {"image y", "1", [](const PairedSample& s) { return s.y; }, nullptr},
      {"image position", "px", [](const PairedSample& s) { return s.u; }, [](const PairedSample& s) { return s.v; }},
      {"time", "s", [](const PairedSample& s) { return s.time_s; }, nullptr},
      {"board tilt", "deg", [](const PairedSample& s) { return s.tilt_deg; }, nullptr},
      {"depth gradient", "raw/px", [](const PairedSample& s) { return std::hypot(s.gradient_u, s.gradient_v); },
       nullptr},
      {"gradient along u", "raw/px", [](const PairedSample& s) { return s.gradient_u; }, nullptr},
      {"gradient along v", "raw/px", [](const PairedSample& s) { return s.gradient_v; }, nullptr},
      {"raw change with motion", "raw/s", [](const PairedSample& s) { return s.raw_rate; }, nullptr},
      {"albedo", "1", [](const PairedSample& s) { return s.albedo; }, nullptr},
  };
  return axes;
}

// Whether an axis takes more than one value over the samples. One that does
// not (time in a toolbox's frame folder, which has no timestamps) explains
// nothing, and its profile's groups would follow the poses' order instead.
bool Varies(const CovariateAxis& axis, const std::vector<PairedSample>& samples) {
  const auto differs = [&](const std::function<double(const PairedSample&)>& value) {
    for (const auto& s : samples)
      if (std::isfinite(value(s)) && value(s) != value(samples.front())) return true;
    return false;
  };
  return !samples.empty() && (differs(axis.value) || (axis.second && differs(axis.second)));
}

// Covariates that a pose mostly has one value of: a depth-dependent or
// time-dependent error is then one offset per pose.
bool IsPoseLevelAxis(const std::string& name) { return name == "raw" || name == "depth" || name == "time"; }

// A covariate as binned: to 9 significant digits. Many samples share a value
// (gradients of integer raw values), and last-bit noise upstream would
// otherwise move some of them across an edge that is one of those values.
double Binned(double v) { return RoundToSignificantDigits(v, 9); }

// Bin index per sample: quantile bins of one axis, or a grid over two.
std::vector<int> Bins(const CovariateAxis& axis, const std::vector<PairedSample>& samples, int bins, int& count) {
  const auto edges = [&](const std::function<double(const PairedSample&)>& f, int n) {
    std::vector<double> values;
    for (const auto& s : samples) values.push_back(Binned(f(s)));
    std::sort(values.begin(), values.end());
    std::vector<double> e;
    for (int k = 1; k < n; ++k)
      e.push_back(values[values.size() * static_cast<std::size_t>(k) / static_cast<std::size_t>(n)]);
    return e;
  };
  const auto locate = [](const std::vector<double>& e, double v) {
    return static_cast<int>(std::upper_bound(e.begin(), e.end(), Binned(v)) - e.begin());
  };
  std::vector<int> bin;
  if (axis.second) {
    const int n = std::max(2, bins / 2);
    const auto eu = edges(axis.value, n), ev = edges(axis.second, n);
    for (const auto& s : samples) bin.push_back(locate(ev, axis.second(s)) * n + locate(eu, axis.value(s)));
    count = n * n;
  } else {
    const auto e = edges(axis.value, bins);
    for (const auto& s : samples) bin.push_back(locate(e, axis.value(s)));
    count = bins;
  }
  return bin;
}

// Mean gain per pose over its standard error.
double Significance(const std::map<int, double>& gain_by_pose) {
  const double n = static_cast<double>(gain_by_pose.size());
  if (n < 3) return 0;
  double mean = 0, sq = 0;
  for (const auto& [pose, g] : gain_by_pose) mean += g / n;
  for (const auto& [pose, g] : gain_by_pose) sq += (g - mean) * (g - mean);
  const double se = std::sqrt(sq / (n - 1) / n);
  return se > 0 ? mean / se : 0;
}

CovariateFinding Analyse(const CovariateAxis& axis, const std::vector<PairedSample>& samples,
                         const std::vector<double>& residual, const std::vector<int>& fold, int folds, int bins,
                         double excess) {
  CovariateFinding finding;
  finding.covariate = axis.name;
  finding.unit = axis.unit;
  int count = 0;
  const std::vector<int> bin = Bins(axis, samples, bins, count);
  // Bin means from the other folds predict each fold's residuals.
  std::vector<std::vector<double>> sum(static_cast<std::size_t>(folds), std::vector<double>(count, 0.0));
  std::vector<std::vector<double>> n(static_cast<std::size_t>(folds), std::vector<double>(count, 0.0));
  std::vector<double> total_sum(count, 0.0), total_n(count, 0.0), centre(count, 0.0);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!std::isfinite(residual[i])) continue;
    sum[fold[i]][bin[i]] += residual[i], n[fold[i]][bin[i]] += 1;
    total_sum[bin[i]] += residual[i], total_n[bin[i]] += 1;
    centre[bin[i]] += axis.value(samples[i]);
  }
  std::map<int, double> gain_by_pose;
  double explained = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!std::isfinite(residual[i])) continue;
    const int b = bin[i];
    const double others = total_n[b] - n[fold[i]][b];
    const double prediction = others > 0 ? (total_sum[b] - sum[fold[i]][b]) / others : 0;
    const double gain = residual[i] * residual[i] - (residual[i] - prediction) * (residual[i] - prediction);
    gain_by_pose[samples[i].pose] += gain;
    explained += gain;
  }
  finding.explained_share = excess > 0 ? std::clamp(explained / excess, 0.0, 1.0) : 0;
  finding.significance = Significance(gain_by_pose);
  std::vector<double> gains;
  for (const auto& [pose, g] : gain_by_pose) gains.push_back(g);
  finding.p_value = SignedRankPValue(gains);
  if (!axis.second) {
    for (int b = 0; b < count; ++b) {
      if (total_n[b] == 0) continue;
      finding.bin_centre.push_back(centre[b] / total_n[b]);
      finding.bin_mean.push_back(total_sum[b] / total_n[b]);
      finding.bin_count.push_back(total_n[b]);
    }
  }
  return finding;
}

struct PoseMeans {
  std::vector<double> residual, covariate, count;
};

PoseMeans MeansByPose(const CovariateAxis& axis, const std::vector<PairedSample>& samples,
                      const std::vector<double>& residual) {
  struct Sums {
    double residual = 0, covariate = 0, n = 0;
  };
  std::map<int, Sums> by_pose;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!std::isfinite(residual[i])) continue;
    Sums& p = by_pose[samples[i].pose];
    p.residual += residual[i], p.covariate += axis.value(samples[i]), p.n += 1;
  }
  PoseMeans m;
  for (const auto& [pose, p] : by_pose) {
    m.residual.push_back(p.residual / p.n);
    m.covariate.push_back(p.covariate / p.n);
    m.count.push_back(p.n);
  }
  return m;
}

// Each pose's mean held-out residual against its mean covariate, tested over
// poses (lab/stats/pose_tests.h) at `p_value`; `explained` is the test's share
// of the squares counted over samples. The profile shows the poses
// themselves, by covariate (few enough to show).
CovariateFinding PoseLevelFinding(const CovariateAxis& axis, const PoseMeans& m, const std::string& level,
                                  double p_value, double explained, double excess) {
  CovariateFinding finding;
  finding.covariate = axis.name;
  finding.unit = axis.unit;
  finding.level = level;
  finding.explained_share = excess > 0 ? std::clamp(explained / excess, 0.0, 1.0) : 0;
  finding.p_value = p_value;
  finding.significance = kNaN;  // this level has only its permutation test
  std::vector<std::size_t> order(m.residual.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return m.covariate[a] < m.covariate[b]; });
  for (std::size_t k : order) {
    finding.bin_centre.push_back(m.covariate[k]);
    finding.bin_mean.push_back(m.residual[k]);
    finding.bin_count.push_back(m.count[k]);
  }
  return finding;
}

// The raw level where a step best fits the held-out residuals against the
// raw value, together with a common slope (the base form, refitted with the
// step, takes up the slope a fit without it leaves around the step). Prefix
// sums over the samples sorted by raw; levels between the 5th and 95th
// percentile: where a firmware-table seam would sit.
double BestStepLevel(const std::vector<PairedSample>& samples, const std::vector<double>& residual) {
  std::vector<std::pair<double, double>> by_raw;
  for (std::size_t i = 0; i < samples.size(); ++i)
    if (std::isfinite(residual[i])) by_raw.emplace_back(samples[i].raw, residual[i]);
  if (by_raw.size() < 20) return kNaN;
  std::sort(by_raw.begin(), by_raw.end());
  struct Sums {
    double n = 0, x = 0, xx = 0, r = 0, xr = 0;
    void Add(double xi, double ri, double sign) {
      n += sign, x += sign * xi, xx += sign * xi * xi, r += sign * ri, xr += sign * xi * ri;
    }
  };
  const double x0 = by_raw[by_raw.size() / 2].first;  // centred: sums of squares stay well conditioned
  Sums below, above;
  for (const auto& [raw, r] : by_raw) above.Add(raw - x0, r, 1);
  double best = -1, level = kNaN;
  for (std::size_t k = 0; k + 1 < by_raw.size(); ++k) {
    below.Add(by_raw[k].first - x0, by_raw[k].second, 1);
    above.Add(by_raw[k].first - x0, by_raw[k].second, -1);
    if (k < by_raw.size() / 20 || k > by_raw.size() * 19 / 20 || by_raw[k + 1].first == by_raw[k].first) continue;
    // Two intercepts and one slope: explained = sum n_g mean_g^2 + Sxr_within^2 / Sxx_within.
    double explained = 0, sxx = 0, sxr = 0;
    for (const Sums* g : {&below, &above}) {
      explained += g->r * g->r / g->n;
      sxx += g->xx - g->x * g->x / g->n;
      sxr += g->xr - g->x * g->r / g->n;
    }
    if (sxx > 0) explained += sxr * sxr / sxx;
    if (explained > best) best = explained, level = 0.5 * (by_raw[k].first + by_raw[k + 1].first);
  }
  return level;
}

Coverage AssessCoverage(const DiagnosisOptions& options, const std::vector<PairedSample>& samples, const DepthFit& fit,
                        double floor_raw, double held_out_rms) {
  Coverage c;
  c.cell_px = options.coverage_cell_px;
  c.min_poses = options.min_poses_per_cell;
  c.parameters = static_cast<int>(fit.parameters.size());
  c.in_sample_rms = fit.raw.rms;
  const model::DepthModel model = fit.Model();  // Effects() is the model's: keep it alive over the loop
  for (const auto& effect : model.Effects())
    for (const std::string& read : effect->CovariatesRead()) c.model_reads.insert(read);
  const auto cell_of = [&](double px) { return std::max(0, static_cast<int>(px / c.cell_px)); };
  const auto placed = [](const PairedSample& s) { return std::isfinite(s.u) && std::isfinite(s.v); };
  c.cells_u = cell_of(options.image_width_px - 1) + 1, c.cells_v = cell_of(options.image_height_px - 1) + 1;
  for (const auto& s : samples)
    if (placed(s)) c.cells_u = std::max(c.cells_u, cell_of(s.u) + 1), c.cells_v = std::max(c.cells_v, cell_of(s.v) + 1);
  std::vector<std::set<int>> reached(static_cast<std::size_t>(c.cells_u * c.cells_v));
  std::set<int> poses;
  for (const auto& s : samples) {
    if (!placed(s)) continue;
    reached[static_cast<std::size_t>(cell_of(s.v) * c.cells_u + cell_of(s.u))].insert(s.pose);
    poses.insert(s.pose);
  }
  c.poses = static_cast<int>(poses.size());
  for (int k = 0; k < c.cells_u * c.cells_v; ++k) {
    const std::set<int>& cell = reached[static_cast<std::size_t>(k)];
    c.poses_per_cell.push_back(static_cast<int>(cell.size()));
    if (cell.empty()) {
      ++c.empty_cells;
    } else if (static_cast<int>(cell.size()) < c.min_poses) {
      const int u0 = static_cast<int>((k % c.cells_u) * c.cell_px), v0 = static_cast<int>((k / c.cells_u) * c.cell_px);
      c.sparse.push_back(
          {u0, v0, u0 + static_cast<int>(c.cell_px), v0 + static_cast<int>(c.cell_px), {cell.begin(), cell.end()}});
    }
  }
  // The cells fewest poses reach first: where one more pose helps most.
  std::stable_sort(c.sparse.begin(), c.sparse.end(),
                   [](const auto& a, const auto& b) { return a.poses.size() < b.poses.size(); });
  // Held out, each pose is predicted by parameters the other poses measured;
  // in-sample, by parameters it helped measure. A model that reaches the
  // floor only in-sample has parameters the poses do not pin down.
  const double excess = held_out_rms * held_out_rms - floor_raw * floor_raw;
  const double gap = held_out_rms * held_out_rms - c.in_sample_rms * c.in_sample_rms;
  c.under_determined = floor_raw > 0 && held_out_rms > options.complete_ratio * floor_raw &&
                       c.in_sample_rms <= options.complete_ratio * floor_raw &&
                       gap >= options.under_determined_share * excess;
  return c;
}

// The covariates (model/covariates.h names) that take one value over every
// sample: an effect reading only those is one offset, the base form's.
std::set<std::string> ConstantCovariates(const std::vector<PairedSample>& samples) {
  std::set<std::string> constant;
  if (samples.empty()) return constant;
  const model::Covariates first = CovariatesOf(samples.front());
  for (const auto& field : model::kCovariateFields) constant.insert(field.name);
  for (const auto& s : samples) {
    const model::Covariates c = CovariatesOf(s);
    for (const auto& field : model::kCovariateFields)
      if (c.*field.field != first.*field.field) constant.erase(field.name);
  }
  return constant;
}

std::vector<std::pair<std::string, model::ModelDefinition>> CandidateModels(const model::ModelDefinition& current,
                                                                            const std::vector<PairedSample>& samples) {
  std::vector<std::pair<std::string, model::ModelDefinition>> out;
  // A millimetre session is fitted in linear_mm, a raw one in a disparity form.
  const bool millimetre = current.form == model::BaseForm::kLinearMm;
  const std::set<std::string> constant = ConstantCovariates(samples);
  for (const auto& info : model::EffectCatalogue()) {
    bool present = false;
    for (const auto& e : current.effects) present = present || e.name == info.name;
    const auto reads = info.create()->CovariatesRead();
    const bool blind = std::all_of(reads.begin(), reads.end(), [&](const auto& r) { return constant.count(r); });
    if (present || !info.AppliesTo(millimetre) || blind) continue;
    model::ModelDefinition d = current;
    model::EffectSpec effect;
    effect.name = info.name;
    d.effects.push_back(effect);
    out.emplace_back(info.name, d);
  }
  if (current.form != model::BaseForm::kLinearMm) {
    for (model::BaseForm form : {model::BaseForm::kReciprocal, model::BaseForm::kTangent}) {
      if (form == current.form) continue;
      model::ModelDefinition d = current;
      d.form = form;
      out.emplace_back(std::string("base_form:") + model::Info(form).name, d);
    }
  }
  return out;
}

// The current model with two candidates' changes: both effects, or an
// effect and another base form. Empty when they are the same change.
std::optional<model::ModelDefinition> CombinedModel(const model::ModelDefinition& current,
                                                    const model::ModelDefinition& first,
                                                    const model::ModelDefinition& second) {
  model::ModelDefinition both = first;
  if (second.form != current.form) both.form = second.form;
  for (const auto& e : second.effects) {
    bool present = false;
    for (const auto& f : both.effects) present = present || f.name == e.name;
    if (!present) both.effects.push_back(e);
  }
  if (both.Describe() == first.Describe()) return std::nullopt;
  return both;
}

// What a candidate is and which covariates it reads, from the catalogue.
void Describe(Candidate& c) {
  if (c.name.rfind("base_form:", 0) == 0) {
    c.doc = "another base form for the raw-to-depth relation";
    return;
  }
  for (const auto& info : model::EffectCatalogue()) {
    if (info.name != c.name) continue;
    c.doc = info.doc;
    c.reads = info.create()->CovariatesRead();
  }
}

// Where the held-out residuals depart from the floor: the floor itself, the
// poses' coverage, every covariate's profile (by sample, and by pose mean for
// the pose-level axes, most explaining first) and the best raw step.
void AnalyseResiduals(const DiagnosisOptions& options, const std::vector<PairedSample>& samples, const DepthFit& fit,
                      const std::vector<double>& grid_std_error_raw, Diagnosis& d) {
  d.floor = EstimateFloor(options, samples, fit, grid_std_error_raw);
  d.held_out_rms = fit.held_out_raw.rms;
  d.held_out_mm = fit.held_out_mm.rms;
  d.ratio_to_floor = d.floor.floor_raw > 0 ? d.held_out_rms / d.floor.floor_raw : 0;
  d.complete = d.ratio_to_floor <= options.complete_ratio;
  d.coverage = AssessCoverage(options, samples, fit, d.floor.floor_raw, d.held_out_rms);
  const std::vector<int> fold = FoldsByPose(samples, options.folds);
  const int folds = fold.empty() ? 1 : *std::max_element(fold.begin(), fold.end()) + 1;
  double squares = 0, finite = 0;
  for (double r : fit.held_out_residual_raw)
    if (std::isfinite(r)) squares += r * r, finite += 1;
  const double excess = squares - finite * d.floor.floor_raw * d.floor.floor_raw;
  for (const auto& axis : Axes()) {
    if (!Varies(axis, samples)) continue;
    d.covariates.push_back(Analyse(axis, samples, fit.held_out_residual_raw, fold, folds, options.bins, excess));
    if (!IsPoseLevelAxis(axis.name)) continue;
    const PoseMeans means = MeansByPose(axis, samples, fit.held_out_residual_raw);
    const ProfileTest profile = PoseProfileTest(means.covariate, means.residual, options.pose_profile_bins);
    double held_out = 0;  // each pose's samples at its held-out profile value
    for (std::size_t k = 0; k < means.residual.size(); ++k)
      held_out +=
          means.count[k] * (std::pow(means.residual[k], 2) - std::pow(means.residual[k] - profile.prediction[k], 2));
    d.covariates.push_back(PoseLevelFinding(axis, means, "pose means", profile.p_value, held_out, excess));
    // A step in the raw value (depth orders the poses alike): the profile's
    // groups of neighbouring poses straddle it. Its share is what it explains
    // beyond chance, each pose counting its mean number of samples.
    if (std::string(axis.name) == "raw") {
      const ProfileTest step = PoseStepTest(means.covariate, means.residual);
      const double per_pose = std::accumulate(means.count.begin(), means.count.end(), 0.0) /
                              static_cast<double>(std::max<std::size_t>(1, means.count.size()));
      d.covariates.push_back(PoseLevelFinding(axis, means, "pose means, step", step.p_value,
                                              per_pose * (step.gain - step.chance_gain), excess));
    }
  }
  std::sort(d.covariates.begin(), d.covariates.end(),
            [](const auto& a, const auto& b) { return a.explained_share > b.explained_share; });
  d.step_level_raw = BestStepLevel(samples, fit.held_out_residual_raw);
}

// How much better `with` predicts the held-out samples than `reference`:
// the share of RMS it removes and the per-pose gain's significance.
struct Gain {
  double reduction = 0, significance = 0, p_value = 1;
  int poses_better = 0, poses = 0;
  bool any = false;
};

Gain GainOver(const std::vector<PairedSample>& subset, const std::vector<double>& reference,
              const std::vector<double>& with) {
  std::map<int, double> gain_by_pose;
  std::map<int, std::pair<double, double>> squares_by_pose;  // without, with
  double current = 0, next = 0;
  Gain g;
  for (std::size_t j = 0; j < subset.size(); ++j) {
    const double a = reference[j], b = with[j];
    if (!std::isfinite(a) || !std::isfinite(b)) continue;
    current += a * a, next += b * b, g.any = true;
    gain_by_pose[subset[j].pose] += a * a - b * b;
    squares_by_pose[subset[j].pose].first += a * a;
    squares_by_pose[subset[j].pose].second += b * b;
  }
  if (g.any && current > 0) g.reduction = 1 - std::sqrt(next / current);
  g.significance = Significance(gain_by_pose);
  // Each pose counts once, as the log of its RMS ratio: a far pose whose
  // error halves weighs as much as a near one whose error halves.
  std::vector<double> log_ratio;
  for (const auto& [pose, sq] : squares_by_pose) {
    if (!(sq.first > 0) || !(sq.second > 0)) continue;
    log_ratio.push_back(0.5 * std::log(sq.first / sq.second));
    g.poses_better += log_ratio.back() > 0;
  }
  g.poses = static_cast<int>(log_ratio.size());
  g.p_value = SignedRankPValue(log_ratio);
  return g;
}

// What every candidate is compared on: an even subsample, the fit options,
// and the current model's held-out residuals fitted the same way (same
// subsample, folds and iterations), not its full fit's: a rich current model
// held out on all samples would make every candidate look worse.
struct Comparison {
  std::vector<std::size_t> chosen;  // indices of the subsample in the session's samples
  std::vector<PairedSample> subset;
  DepthFitOptions fit_options;
  std::vector<double> baseline;
  // The current model with the cameras free to move within their
  // uncertainty: what a candidate must also beat (none without perturbations).
  std::optional<std::vector<double>> cameras_free;
};

// The candidates' subsample and fit options; no fit yet.
Comparison ComparisonSubset(const DiagnosisOptions& options, const std::vector<PairedSample>& samples) {
  Comparison in;
  const std::size_t stride = EvenStride(samples.size(), options.max_candidate_samples);
  for (std::size_t i = 0; i < samples.size(); i += stride) in.chosen.push_back(i);
  for (std::size_t i : in.chosen) in.subset.push_back(samples[i]);
  in.fit_options.folds = options.folds;
  in.fit_options.millimetre_readings = options.millimetre_readings;
  in.fit_options.max_iterations = 30;  // a ranking needs the error to a few per cent, not the last digit
  return in;
}

void CurrentModelRefit(const DepthFit& fit, Comparison& in, Diagnosis& d) {
  in.baseline.assign(in.subset.size(), std::nan(""));
  const StepClock current_clock;
  if (const auto refit = RunHeldOutFit(in.fit_options, fit.definition, in.subset); Accepted(refit)) {
    in.baseline = std::get<HeldOutFit>(refit).held_out_residual_raw;
  } else {
    for (std::size_t j = 0; j < in.chosen.size(); ++j) in.baseline[j] = fit.held_out_residual_raw[in.chosen[j]];
  }
  d.seconds.current_refit = current_clock.Seconds();
}

// Sets in.cameras_free and the cameras' shifts; their share of the error
// is compared with the current model's once both are known.
void FitWithCamerasFree(const DiagnosisOptions& options, const DepthFit& fit, const DepthPerturbations& perturbations,
                        Comparison& in, Diagnosis& d) {
  const StepClock cameras_clock;
  if (!perturbations.empty()) {
    DepthPerturbations moved(perturbations.size());
    for (std::size_t k = 0; k < perturbations.size(); ++k)
      for (std::size_t i : in.chosen) moved[k].push_back(perturbations[k][i]);
    DepthFitOptions free_options = in.fit_options;
    free_options.camera_freedom_sigma = options.camera_freedom_sigma;
    if (const auto r = RunDepthModelFit(free_options, fit.definition, in.subset, moved); Accepted(r)) {
      const DepthFit& free_fit = std::get<DepthFit>(r);
      in.cameras_free = free_fit.held_out_residual_raw;
      d.camera_shift_sigma = free_fit.camera_shift_sigma;
    }
  }
  d.seconds.cameras_free = cameras_clock.Seconds();
}

// A fitted candidate's gain over the current model, and beyond the cameras.
void JudgeCandidate(const Comparison& in, const StageResult<HeldOutFit>& result, const Diagnosis& d, Candidate& c) {
  if (!Accepted(result)) {
    c.not_fitted = std::get<Rejection>(result).reason;
    return;
  }
  const HeldOutFit& candidate = std::get<HeldOutFit>(result);
  const Gain g = GainOver(in.subset, in.baseline, candidate.held_out_residual_raw);
  if (!g.any) {
    c.not_fitted = "no held-out sample to compare with the current model";
    return;
  }
  c.parameters = static_cast<int>(candidate.parameters);
  c.reduction = g.reduction;
  c.held_out_rms = d.held_out_rms * (1 - c.reduction);
  c.held_out_mm = d.held_out_mm * (1 - c.reduction);
  c.significance = g.significance;
  c.p_value = g.p_value;
  c.poses_better = g.poses_better;
  c.poses_compared = g.poses;
  const Gain beyond = in.cameras_free ? GainOver(in.subset, *in.cameras_free, candidate.held_out_residual_raw) : g;
  c.reduction_beyond_cameras = beyond.reduction;
  c.significance_beyond_cameras = beyond.significance;
  c.p_value_beyond_cameras = beyond.p_value;
}

// Every candidate on its own, fitted and held out by pose on the subsample,
// side by side with the current model's refit and its fit with the cameras
// free (what each candidate is compared with): the largest candidate starts
// at once instead of after those two (Herrera's formula refit: its
// diagnosis 5.7 -> see README). Into d.candidates; returns each fitted
// one's held-out residuals (for the pair search).
std::map<std::string, std::vector<double>> FitCandidates(
    const DiagnosisOptions& options, const std::vector<std::pair<std::string, model::ModelDefinition>>& models,
    const DepthFit& fit, const DepthPerturbations& perturbations, Comparison& in, Diagnosis& d) {
  d.candidates.resize(models.size());
  std::vector<std::optional<StageResult<HeldOutFit>>> results(models.size());
  const StepClock candidates_clock;
  std::optional<StepProgress> progress(std::in_place, "diagnosis: candidate", static_cast<int>(models.size()));
  // Largest first: the pattern's folds take most of the time, and started
  // last they ran on one core while the other was idle.
  std::vector<std::size_t> order(models.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return model::DepthModel(models[a].second).Flat().size() > model::DepthModel(models[b].second).Flat().size();
  });
  tbb::parallel_invoke(
      [&] {
        tbb::parallel_for(std::size_t{0}, models.size(), [&](std::size_t i) {
          const std::size_t k = order[i];
          const StepClock clock;
          results[k] = RunHeldOutFit(in.fit_options, models[k].second, in.subset);
          d.candidates[k].seconds = clock.Seconds();
          progress->Done(models[k].first);
        });
      },
      [&] {
        CurrentModelRefit(fit, in, d);
        FitWithCamerasFree(options, fit, perturbations, in, d);
      });
  progress.reset();
  d.seconds.candidates = candidates_clock.Seconds();
  if (in.cameras_free)
    d.cameras_free_held_out_rms = d.held_out_rms * (1 - GainOver(in.subset, in.baseline, *in.cameras_free).reduction);
  std::map<std::string, std::vector<double>> held_out_with;
  for (std::size_t k = 0; k < models.size(); ++k) {
    d.candidates[k].name = models[k].first;
    Describe(d.candidates[k]);
    if (const auto* held = std::get_if<HeldOutFit>(&*results[k]))
      held_out_with[models[k].first] = held->held_out_residual_raw;
    JudgeCandidate(in, *results[k], d, d.candidates[k]);
  }
  return held_out_with;
}

// Fitted candidates first, best first; those not fitted keep their order.
// Among those near the best, the one with fewest parameters leads.
void RankCandidates(const DiagnosisOptions& options, Diagnosis& d) {
  std::stable_sort(d.candidates.begin(), d.candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.Fitted() != b.Fitted() ? a.Fitted() : a.Fitted() && a.reduction > b.reduction;
  });
  if (d.candidates.empty()) return;
  const double near_best = d.candidates.front().held_out_rms * (1 + options.parsimony_share);
  auto simplest = d.candidates.begin();
  for (auto c = d.candidates.begin(); c != d.candidates.end(); ++c)
    if (c->Fitted() && c->reduction >= options.min_reduction && c->held_out_rms <= near_best &&
        c->parameters < simplest->parameters)
      simplest = c;
  std::rotate(d.candidates.begin(), simplest, simplest + 1);
}

// One effect not enough: the recommended one with each other helpful
// candidate, judged against the recommended one alone by the same test.
void SearchPairs(const DiagnosisOptions& options, const model::ModelDefinition& current,
                 const std::vector<std::pair<std::string, model::ModelDefinition>>& models, const Comparison& in,
                 const std::vector<double>& single, Diagnosis& d) {
  const auto recommended_model =
      std::find_if(models.begin(), models.end(), [&](const auto& m) { return m.first == *d.recommended; });
  std::vector<std::pair<std::string, model::ModelDefinition>> pairs;
  for (const auto& c : d.candidates) {
    if (c.recommended || c.reduction < options.min_reduction || pairs.size() >= options.max_pair_candidates) continue;
    const auto other = std::find_if(models.begin(), models.end(), [&](const auto& m) { return m.first == c.name; });
    if (other == models.end()) continue;
    if (auto both = CombinedModel(current, recommended_model->second, other->second)) pairs.emplace_back(c.name, *both);
  }
  std::vector<PairFinding> found(pairs.size());
  const StepClock pairs_clock;
  StepProgress pair_progress("diagnosis: pair", static_cast<int>(pairs.size()));
  tbb::parallel_for(std::size_t{0}, pairs.size(), [&](std::size_t k) {
    found[k].second = pairs[k].first;
    const StepClock clock;
    const auto result = RunHeldOutFit(in.fit_options, pairs[k].second, in.subset);
    found[k].seconds = clock.Seconds();
    pair_progress.Done(pairs[k].first);
    if (!Accepted(result)) return;
    const std::vector<double>& held_out = std::get<HeldOutFit>(result).held_out_residual_raw;
    const Gain over_single = GainOver(in.subset, single, held_out);
    const Gain over_current = GainOver(in.subset, in.baseline, held_out);
    found[k].fitted = over_single.any;
    found[k].held_out_rms = d.held_out_rms * (1 - over_current.reduction);
    found[k].reduction_over_single = over_single.reduction;
    found[k].p_value = over_single.p_value;
    found[k].poses_better = over_single.poses_better;
    found[k].poses_compared = over_single.poses;
  });
  std::erase_if(found, [](const PairFinding& f) { return !f.fitted; });
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.held_out_rms < b.held_out_rms; });
  if (!found.empty()) d.best_pair = found.front();
  d.seconds.pairs = pairs_clock.Seconds();
}

}  // namespace

Diagnosis RunModelDiagnosis(const DiagnosisOptions& options, const std::vector<PairedSample>& samples,
                            const DepthFit& fit, const DepthPerturbations& perturbations,
                            const std::vector<double>& grid_std_error_raw) {
  const StepClock total_clock;
  Diagnosis d;
  d.reading_unit = options.millimetre_readings ? "mm read" : "raw";
  AnalyseResiduals(options, samples, fit, grid_std_error_raw, d);
  d.seconds.residual_analysis = total_clock.Seconds();
  Comparison in = ComparisonSubset(options, samples);
  const auto models = CandidateModels(fit.definition, samples);
  const auto held_out_with = FitCandidates(options, models, fit, perturbations, in, d);
  RankCandidates(options, d);
  ConcludeDiagnosis(options, d);
  if (d.recommended && held_out_with.count(*d.recommended)) {
    SearchPairs(options, fit.definition, models, in, held_out_with.at(*d.recommended), d);
    DescribePair(options, d);
  }
  d.seconds.total = total_clock.Seconds();
  return d;
}

}  // namespace speckle
