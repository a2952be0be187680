#include "apps/calibration_check.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>

#include "lab/fit/fit_samples.h"
#include "model/depth_model.h"
#include "model/undistortion_grid.h"
#include "stages/outline_calibration.h"

namespace speckle {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const char* const kRegionNames[3][3] = {
    {"top left", "top", "top right"}, {"left", "centre", "right"}, {"bottom left", "bottom", "bottom right"}};

// One board sample as the calibration reads it.
struct Scored {
  int pose = 0;
  double depth_m = 0, error_m = 0, raw_step_m = 0;
  double u = 0, v = 0;
};

double ModelDepth(const apply::DepthCalibration& calibration, model::Covariates c, double raw) {
  c.raw = calibration.grid ? calibration.grid->Apply(raw, c.x, c.y) : raw;
  return calibration.model->Depth(c);
}

// The depth of one step of what the sensor measures, at `depth`: one raw
// value by the calibration's model; under the driver's millimetres, one of
// the 11-bit raw values they were converted from (the nominal Kinect
// relation 1/z = -0.0030711 r + 3.3309, dz = 0.0030711 z^2 per value), not
// the millimetre the driver rounds to.
double RawStep(const apply::DepthCalibration& calibration, const model::Covariates& c, double raw, double depth) {
  if (calibration.depth_units == DepthUnits::kMillimetre) return 0.0030711 * depth * depth;
  return std::abs(ModelDepth(calibration, c, raw + 0.5) - ModelDepth(calibration, c, raw - 0.5));
}

std::vector<Scored> Score(const apply::DepthCalibration& calibration, const std::vector<PairedSample>& samples) {
  std::vector<Scored> out;
  out.reserve(samples.size());
  for (const PairedSample& s : samples) {
    const model::Covariates c = CovariatesOf(s);
    const double depth = ModelDepth(calibration, c, s.raw);
    if (!std::isfinite(depth)) continue;
    out.push_back({s.pose, s.depth_m, depth - s.depth_m, RawStep(calibration, c, s.raw, depth), s.u, s.v});
  }
  return out;
}

double Median(std::vector<double> values) {
  if (values.empty()) return kNaN;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// Mean and standard error of per-pose means (poses are the independent units).
struct PoseMean {
  double mean = 0, standard_error = kNaN;
  int poses = 0;
};
PoseMean OverPoses(const std::map<int, std::vector<double>>& by_pose) {
  std::vector<double> means;
  for (const auto& [pose, values] : by_pose) {
    double sum = 0;
    for (double v : values) sum += v;
    means.push_back(sum / static_cast<double>(values.size()));
  }
  PoseMean out;
  out.poses = static_cast<int>(means.size());
  if (means.empty()) return out;
  for (double m : means) out.mean += m / out.poses;
  if (out.poses < 2) return out;
  double ss = 0;
  for (double m : means) ss += (m - out.mean) * (m - out.mean);
  out.standard_error = std::sqrt(ss / (out.poses - 1) / out.poses);
  return out;
}

// Beyond how many standard errors a mean estimated with `dof` degrees of
// freedom is as rare as a normal one beyond 3 sigma (two-sided 0.27 %):
// Student's t.
double Threshold(double dof) {
  static constexpr double kT[] = {235.78, 19.21, 9.22, 6.62, 5.51, 4.9,  4.53, 4.28, 4.09, 3.96,
                                  3.85,   3.76,  3.69, 3.64, 3.59, 3.54, 3.51, 3.48, 3.45, 3.42,
                                  3.4,    3.38,  3.36, 3.34, 3.33, 3.32, 3.3,  3.29, 3.28, 3.27};
  if (!(dof >= 1)) return kNaN;
  if (dof > 30) return 3 + 8 / dof;  // within 0.01 of t beyond 30
  return kT[static_cast<int>(std::floor(dof)) - 1];
}

// Significant beyond `sigmas` of the combined sigma; then a step or more of
// what the sensor reports recalibrates.
CheckVerdict Judge(double error, double combined_sigma, double step, double sigmas, double* z) {
  *z = error / combined_sigma;
  if (!std::isfinite(*z)) return CheckVerdict::kCannotJudge;
  if (std::abs(*z) <= sigmas) return CheckVerdict::kOk;
  return std::abs(error) < step ? CheckVerdict::kDegraded : CheckVerdict::kRecalibrate;
}

// A depth band or image region: which samples fall in it.
using InCell = std::function<bool(const Scored&)>;

// Both recordings' samples, as the calibration reads them.
struct ScoredSets {
  std::vector<Scored> recording, calibration;  // calibration: its own samples (samples.h5), may be empty
};

// A cell as this recording sees it, before it is judged: each pose's mean
// error in raw units (the error over the depth of one raw unit there), the
// unit in which a pose's error is alike at every depth (a colour pose's
// depth error and a raw unit's depth both grow as z squared).
struct Gathered {
  ErrorCell cell;
  std::vector<double> pose_means_raw;
};

int PosesIn(const std::vector<Scored>& samples, const InCell& in_cell) {
  std::map<int, int> poses;
  for (const Scored& s : samples)
    if (in_cell(s)) ++poses[s.pose];
  return static_cast<int>(poses.size());
}

Gathered Gather(const std::string& where, const ScoredSets& sets, const InCell& in_cell,
                const apply::DepthSigmaTable& sigmas) {
  Gathered g;
  ErrorCell& cell = g.cell;
  cell.where = where;
  std::map<int, std::vector<const Scored*>> by_pose;
  std::vector<double> depths, steps;
  for (const Scored& s : sets.recording) {
    if (!in_cell(s)) continue;
    by_pose[s.pose].push_back(&s);
    depths.push_back(s.depth_m);
    steps.push_back(s.raw_step_m);
  }
  cell.samples = static_cast<int>(depths.size());
  cell.poses = static_cast<int>(by_pose.size());
  double ss = 0;
  int n = 0;
  for (const auto& [pose, in] : by_pose) {
    double mean = 0, mean_raw = 0;
    for (const Scored* s : in) mean += s->error_m / in.size(), mean_raw += s->error_m / s->raw_step_m / in.size();
    for (const Scored* s : in) ss += (s->error_m - mean) * (s->error_m - mean);
    n += static_cast<int>(in.size()) - 1;
    cell.mean_error_m += mean / cell.poses;
    cell.mean_error_raw += mean_raw / cell.poses;
    g.pose_means_raw.push_back(mean_raw);
  }
  cell.reading_noise_m = n > 0 ? std::sqrt(ss / n) : kNaN;
  cell.depth_m = Median(depths);
  cell.raw_step_m = Median(steps);
  cell.calibration_sigma_m = sigmas.depth_m.empty() ? kNaN : sigmas.At(cell.depth_m);
  // Without the calibration's samples, its recording is taken to be like this one.
  cell.calibration_poses = sets.calibration.empty() ? cell.poses : PosesIn(sets.calibration, in_cell);
  return g;
}

// The cells of one kind (depth bands, or regions) judged together: how far
// a pose's mean strays from its cell's is pooled over them (a band seen in
// five poses alone would give its standard error four degrees of freedom,
// itself uncertain by a third). This recording measures a cell's mean to
// that over root(its poses); the calibration's recording pinned it to that
// over root(its poses there), its samples having scattered alike.
std::vector<ErrorCell> JudgeTogether(std::vector<Gathered> gathered, const CheckOptions& options) {
  double ss = 0, dof = 0;
  for (const Gathered& g : gathered) {
    if (g.pose_means_raw.size() < 2) continue;
    for (double x : g.pose_means_raw) ss += (x - g.cell.mean_error_raw) * (x - g.cell.mean_error_raw);
    dof += static_cast<double>(g.pose_means_raw.size()) - 1;
  }
  const double pose_sigma_raw = dof > 0 ? std::sqrt(ss / dof) : kNaN;
  std::vector<ErrorCell> out;
  for (Gathered& g : gathered) {
    ErrorCell& c = g.cell;
    c.standard_error_raw = pose_sigma_raw / std::sqrt(c.poses);
    c.fitted_standard_error_raw = c.calibration_poses > 0 ? pose_sigma_raw / std::sqrt(c.calibration_poses) : kNaN;
    c.z = c.threshold_sigmas = kNaN;
    if (dof < options.min_pooled_dof)
      c.not_judged = fmt::format("too few poses to know how far a pose's mean strays ({:.0f} degrees of freedom)", dof);
    else if (c.calibration_poses == 0)
      c.not_judged = "no board of the calibration's recording was here: its model extrapolates";
    if (c.samples == 0) continue;
    if (c.not_judged.empty()) {
      c.threshold_sigmas = Threshold(dof);
      c.verdict = Judge(c.mean_error_raw, std::hypot(c.standard_error_raw, c.fitted_standard_error_raw), 1.0,
                        c.threshold_sigmas, &c.z);
    }
    out.push_back(std::move(c));
  }
  return out;
}

std::vector<ErrorCell> ByDepth(const ScoredSets& sets, const apply::DepthSigmaTable& sigmas,
                               const CheckOptions& options) {
  std::vector<Gathered> cells;
  const auto& edges = options.depth_edges_m;
  for (std::size_t b = 0; b + 1 < edges.size(); ++b) {
    const InCell in_band = [lo = edges[b], hi = edges[b + 1]](const Scored& s) {
      return s.depth_m >= lo && s.depth_m < hi;
    };
    cells.push_back(Gather(fmt::format("{:.2f}-{:.2f} m", edges[b], edges[b + 1]), sets, in_band, sigmas));
  }
  return JudgeTogether(std::move(cells), options);
}

std::vector<ErrorCell> ByRegion(const ScoredSets& sets, cv::Size size, const apply::DepthSigmaTable& sigmas,
                                const CheckOptions& options) {
  std::vector<Gathered> cells;
  for (int row = 0; row < 3; ++row)
    for (int column = 0; column < 3; ++column) {
      const InCell in_region = [&, row, column](const Scored& s) {
        return std::clamp(static_cast<int>(3 * s.v / size.height), 0, 2) == row &&
               std::clamp(static_cast<int>(3 * s.u / size.width), 0, 2) == column;
      };
      cells.push_back(Gather(kRegionNames[row][column], sets, in_region, sigmas));
    }
  return JudgeTogether(std::move(cells), options);
}

// The outline's corner offsets (found - predicted), per view: their mean,
// and their mean along each corner's outward direction.
struct OutlineOffset {
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();
  double growth = 0, board_depth_m = 0;
};

OutlineOffset Offset(const BoardGeometry& board, const CameraCalibration& cameras, const ExtrinsicsView& view) {
  const auto outline = OutlineCorners(board);
  const double delay = cameras.depth_delay_s.value_or(0), edge = cameras.depth_edge_offset_px.value_or(0);
  OutlineOffset out;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d at_depth_exposure = view.colour_from_board * outline[k] + delay * view.board_velocity;
    const Eigen::Vector2d outward = CornerOutward(view.quad, k);
    const Eigen::Vector2d predicted = cameras.depth.Project(cameras.depth_from_colour * at_depth_exposure);
    const Eigen::Vector2d offset = view.quad.corners_px[k] - (predicted + edge * outward);
    out.shift += offset / 4;
    out.growth += offset.dot(outward.normalized()) / 4;
  }
  out.board_depth_m = (cameras.depth_from_colour * view.colour_from_board).translation().z();
  return out;
}

Registration Register(const PipelineResult& recording, const CameraCalibration& cameras, const CheckOptions& options) {
  Registration out;
  std::map<int, std::vector<double>> shift_u, shift_v, growth;
  std::vector<double> depths;
  int pose = 0;
  for (std::size_t i = 0; i < recording.extrinsics_views.size(); ++i) {
    const ExtrinsicsView& view = recording.extrinsics_views[i];
    const OutlineOffset o = Offset(recording.board, cameras, view);
    // Views carry no pose but come in recording order: consecutive views
    // whose colour poses lie within 5 mm are frames of one still pose.
    if (i > 0 &&
        (view.colour_from_board.translation() - recording.extrinsics_views[i - 1].colour_from_board.translation())
                .norm() > 5e-3)
      ++pose;
    shift_u[pose].push_back(o.shift.x()), shift_v[pose].push_back(o.shift.y()), growth[pose].push_back(o.growth);
    depths.push_back(o.board_depth_m);
    ++out.frames;
  }
  PoseMean u = OverPoses(shift_u), v = OverPoses(shift_v), g = OverPoses(growth);
  if (u.poses == 0) u.mean = v.mean = g.mean = kNaN;  // nothing measured: not a shift of 0
  out.poses = u.poses;
  out.shift_px = {u.mean, v.mean};
  out.shift_standard_error_px = {u.standard_error, v.standard_error};
  out.growth_px = g.mean;
  out.growth_standard_error_px = g.standard_error;
  // Where the calibration's extrinsics put an outline is uncertain by their
  // translation's sigma, seen at the boards' median distance.
  const Eigen::Vector3d t = cameras.extrinsics_translation_sigma_m;
  out.calibration_sigma_px = cameras.depth.camera_matrix(0, 0) * std::hypot(t.x(), t.y()) / Median(depths);
  out.z = kNaN;
  if (out.poses < options.min_outline_poses) {
    out.not_judged = out.poses == 0
                         ? "no board outline was found (a board larger than its chessboard shows none)"
                         : fmt::format("outlines in {} poses, fewer than {}", out.poses, options.min_outline_poses);
    return out;
  }
  const double steps[3] = {out.shift_px.x(), out.shift_px.y(), out.growth_px};
  const double errors[3] = {u.standard_error, v.standard_error, g.standard_error};
  out.verdict = CheckVerdict::kOk;
  for (int k = 0; k < 3; ++k) {
    double z = 0;
    const CheckVerdict verdict =
        Judge(steps[k], std::hypot(errors[k], out.calibration_sigma_px), 1.0, options.significance_sigmas, &z);
    if (!std::isfinite(out.z) || std::abs(z) > std::abs(out.z)) out.z = z;
    out.verdict = std::max(out.verdict, verdict);
  }
  return out;
}

// A wall's corrected points about their least-squares plane.
std::optional<CorrectedWall> Flatness(const apply::DepthCalibration& calibration, const PlanarSnapshot& wall,
                                      cv::Size size) {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::pair<int, int>> cells;
  for (const PlanarPixel& p : wall.inliers) {
    model::Covariates c;
    c.u = p.u, c.v = p.v, c.x = p.x, c.y = p.y;
    const double z = ModelDepth(calibration, c, p.raw);
    if (!std::isfinite(z)) continue;
    points.emplace_back(p.x * z, p.y * z, z);
    cells.emplace_back(std::clamp(static_cast<int>(3 * p.v / size.height), 0, 2),
                       std::clamp(static_cast<int>(3 * p.u / size.width), 0, 2));
  }
  if (points.size() < 100) return std::nullopt;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : points) centre += p / static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) scatter += (p - centre) * (p - centre).transpose();
  const Eigen::Vector3d normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
  CorrectedWall out;
  out.frame = wall.frame, out.depth_m = centre.z(), out.pixels = static_cast<int>(points.size());
  double sum[3][3] = {}, count[3][3] = {}, ss = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double off = normal.dot(points[i] - centre) * (normal.z() < 0 ? -1 : 1);  // + nearer the sensor's far side
    ss += off * off;
    sum[cells[i].first][cells[i].second] += off, count[cells[i].first][cells[i].second] += 1;
  }
  out.rms_m = std::sqrt(ss / static_cast<double>(points.size()));
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (count[r][c] >= 30 && std::abs(sum[r][c] / count[r][c]) > std::abs(out.largest_region_mean_m))
        out.largest_region_mean_m = sum[r][c] / count[r][c], out.largest_region = kRegionNames[r][c];
  return out;
}

void Map(const std::vector<Scored>& scored, cv::Size size, int block, CheckResult& out) {
  out.map_columns = (size.width + block - 1) / block;
  out.map_rows = (size.height + block - 1) / block;
  std::vector<double> sum(static_cast<std::size_t>(out.map_columns * out.map_rows), 0.0), count(sum.size(), 0.0);
  for (const Scored& s : scored) {
    const int column = std::clamp(static_cast<int>(s.u) / block, 0, out.map_columns - 1);
    const int row = std::clamp(static_cast<int>(s.v) / block, 0, out.map_rows - 1);
    sum[static_cast<std::size_t>(row * out.map_columns + column)] += s.error_m;
    count[static_cast<std::size_t>(row * out.map_columns + column)] += 1;
  }
  out.map_error_m.resize(sum.size());
  for (std::size_t i = 0; i < sum.size(); ++i) out.map_error_m[i] = count[i] > 0 ? sum[i] / count[i] : kNaN;
}

std::string Reason(const ErrorCell& c, const char* kind) {
  return fmt::format(
      "{} {}: {:+.2f} raw units (about {:+.1f} mm at its {:.2f} m) over {} poses, {:.1f} sigma (this "
      "recording ± {:.2f}, the calibration's ± {:.2f})",
      kind, c.where, c.mean_error_raw, 1e3 * c.mean_error_raw * c.raw_step_m, c.depth_m, c.poses, std::abs(c.z),
      c.standard_error_raw, c.fitted_standard_error_raw);
}

// The worst judgement, and what made it, worst first.
std::string RegistrationReason(const Registration& r) {
  return fmt::format(
      "registration: the depth outlines lie ({:+.2f}, {:+.2f}) px from where the colour poses and the "
      "extrinsics put them, grown {:+.2f} px, {:.1f} sigma over {} poses",
      r.shift_px.x(), r.shift_px.y(), r.growth_px, std::abs(r.z), r.poses);
}

int Judged(const std::vector<ErrorCell>& cells) {
  int n = 0;
  for (const auto& c : cells) n += std::isfinite(c.z);
  return n;
}

// The worst judgement and what made it, worst first. A change found is
// said however little could be judged; OK needs a depth band judged at
// least (a drift or a scale moves every depth), else it cannot be judged.
void Conclude(CheckResult& out) {
  std::vector<std::pair<double, std::string>> reasons;
  out.verdict = CheckVerdict::kOk;
  const auto take = [&](CheckVerdict v, double z, const std::string& why) {
    if (v == CheckVerdict::kCannotJudge) return;
    out.verdict = std::max(out.verdict, v);
    if (v != CheckVerdict::kOk) reasons.emplace_back(-std::abs(z), ToString(v) + ": " + why);
  };
  for (const auto& c : out.by_depth) take(c.verdict, c.z, Reason(c, "depth"));
  for (const auto& c : out.by_region) take(c.verdict, c.z, Reason(c, "region"));
  const Registration& r = out.registration;
  take(r.verdict, r.z, RegistrationReason(r));
  std::sort(reasons.begin(), reasons.end());
  for (auto& [z, why] : reasons) out.reasons.push_back(std::move(why));
  out.judged = fmt::format("{} of {} depth bands, {} of {} regions, {}", Judged(out.by_depth), out.by_depth.size(),
                           Judged(out.by_region), out.by_region.size(),
                           std::isfinite(r.z) ? "the registration" : "not the registration: " + r.not_judged);
  if (out.verdict != CheckVerdict::kOk || Judged(out.by_depth) > 0) return;
  out.verdict = CheckVerdict::kCannotJudge;
  out.reasons.push_back(out.by_depth.empty() ? "no board sample was paired"
                                             : "no depth band could be judged: " + out.by_depth.front().not_judged);
}

}  // namespace

CheckResult CheckCalibration(const CheckInput& input, const CheckOptions& options) {
  CheckResult out;
  const PipelineResult& rec = input.recording;
  const cv::Size size = input.cameras.depth.image_size;
  ScoredSets sets{Score(input.calibration, rec.samples), {}};
  if (input.calibration_samples) sets.calibration = Score(input.calibration, *input.calibration_samples);
  const std::vector<Scored>& scored = sets.recording;
  out.board_frames = rec.board_frames;
  out.paired_frames = rec.paired_frames;
  out.samples = static_cast<int>(scored.size());
  out.by_depth = ByDepth(sets, input.sigmas, options);
  out.by_region = ByRegion(sets, size, input.sigmas, options);
  out.registration = Register(rec, input.cameras, options);
  for (const PlanarSnapshot& wall : rec.snapshots)
    if (auto flat = Flatness(input.calibration, wall, size)) out.walls.push_back(*flat);
  Map(scored, size, options.map_block_px, out);
  Conclude(out);
  return out;
}

std::string ToString(CheckVerdict verdict) {
  switch (verdict) {
    case CheckVerdict::kOk:
      return "OK";
    case CheckVerdict::kDegraded:
      return "DEGRADED";
    case CheckVerdict::kRecalibrate:
      return "RECALIBRATE";
    case CheckVerdict::kCannotJudge:
      break;
  }
  return "CANNOT JUDGE";
}

}  // namespace speckle
