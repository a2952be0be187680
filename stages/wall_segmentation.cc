#include "stages/wall_segmentation.h"

#include "schemas/option_check.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

namespace speckle {
namespace {

constexpr double kNominalA = -0.0030711, kNominalB = 3.3309;  // 1/z = a r + b (1/m)
constexpr const char* kCleanupStage = "planar_cleanup";

struct Sample {
  int cell;
  double x, y, raw;       // raw: on the raw scale, where the tolerances are (millimetres through the nominal relation)
  Eigen::Vector3d point;  // metres, nominal relation; z = 0 when it gives none
  double reading = 0;     // the value as recorded, in its own units
};

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

std::vector<Sample> SampleGrid(const WallSegmentationOptions& o, const CameraIntrinsics& depth, const cv::Mat& raw,
                               const DepthReading& reading, WallMask& mask) {
  mask.crop_px = o.crop_px, mask.stride = o.stride;
  mask.cols = std::max(0, (raw.cols - 2 * o.crop_px + o.stride - 1) / o.stride);
  mask.rows = std::max(0, (raw.rows - 2 * o.crop_px + o.stride - 1) / o.stride);
  mask.wall.assign(static_cast<std::size_t>(mask.cols * mask.rows), 0);
  mask.reading = mask.wall;
  std::vector<Sample> samples;
  for (int j = 0; j < mask.rows; ++j) {
    for (int i = 0; i < mask.cols; ++i) {
      const int u = o.crop_px + i * o.stride, v = o.crop_px + j * o.stride;
      const std::uint16_t r = raw.at<std::uint16_t>(v, u);
      if (!reading.IsReading(r)) continue;
      const Eigen::Vector2d xy = depth.Undistort({u, v});
      if (!xy.allFinite()) continue;
      mask.reading[static_cast<std::size_t>(j * mask.cols + i)] = 1;
      // Millimetre readings are depths already; raw ones through the nominal Kinect.
      const bool millimetres = reading.units() == DepthUnits::kMillimetre;
      const double inverse_z = millimetres ? 1000.0 / r : kNominalA * r + kNominalB;
      const double raw_scale = millimetres ? (inverse_z - kNominalB) / kNominalA : double(r);
      const Eigen::Vector3d point =
          inverse_z > 0.05 ? Eigen::Vector3d(Eigen::Vector3d(xy.x(), xy.y(), 1) / inverse_z) : Eigen::Vector3d::Zero();
      samples.push_back({j * mask.cols + i, xy.x(), xy.y(), raw_scale, point, double(r)});
    }
  }
  return samples;
}

// Raw residual of a sample from the plane n . X = d: the raw value the
// nominal relation gives the plane's depth along the sample's ray.
double PlaneResidualRaw(const Eigen::Vector3d& n, double d, const Sample& s, double cap) {
  const double denominator = n.dot(Eigen::Vector3d(s.x, s.y, 1));
  if (std::abs(denominator) < 1e-12) return cap;
  const double z = d / denominator;
  if (!(z > 0)) return cap;
  return s.raw - (1 / z - kNominalB) / kNominalA;
}

// MSAC over the seed samples (the image's centre); returns the seed inliers.
std::vector<int> DominantPlaneSeed(const WallSegmentationOptions& o, const std::vector<Sample>& samples, int frame) {
  std::vector<int> seed;
  for (int k = 0; k < static_cast<int>(samples.size()); ++k) {
    const Sample& s = samples[static_cast<std::size_t>(k)];
    if (std::abs(s.x) < o.seed_half_width && std::abs(s.y) < o.seed_half_width && s.point.z() > 0) seed.push_back(k);
  }
  if (seed.size() < 50) return {};
  std::mt19937 rng(static_cast<unsigned>(frame) * 7919u + 17u);
  std::uniform_int_distribution<std::size_t> pick(0, seed.size() - 1);
  const double tol = o.msac_tolerance_raw;
  double best_cost = 1e300;
  Eigen::Vector3d best_n = Eigen::Vector3d::UnitZ();
  double best_d = 1;
  for (int it = 0; it < o.msac_iterations; ++it) {
    const Eigen::Vector3d& a = samples[static_cast<std::size_t>(seed[pick(rng)])].point;
    const Eigen::Vector3d& b = samples[static_cast<std::size_t>(seed[pick(rng)])].point;
    const Eigen::Vector3d& c = samples[static_cast<std::size_t>(seed[pick(rng)])].point;
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() < 1e-9) continue;
    n.normalize();
    const double d = n.dot(a);
    // A plane is kept only if it beats the best so far: once its partial
    // cost reaches that, the rest of the seed cannot change the outcome.
    double cost = 0;
    for (std::size_t j = 0; j < seed.size() && cost < best_cost; ++j)
      cost += std::min(std::pow(PlaneResidualRaw(n, d, samples[std::size_t(seed[j])], tol), 2), tol * tol);
    if (cost < best_cost) best_cost = cost, best_n = n, best_d = d;
  }
  std::vector<int> inliers;
  for (const int k : seed)
    if (std::abs(PlaneResidualRaw(best_n, best_d, samples[std::size_t(k)], tol)) < tol) inliers.push_back(k);
  return inliers;
}

// r^2 = q . (1, x, y, x^2, x y, y^2) fitted to the samples `members`.
Eigen::Matrix<double, 6, 1> FitQuadric(const std::vector<Sample>& samples, const std::vector<int>& members) {
  Eigen::Matrix<double, 6, 6> normal = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
  for (const int k : members) {
    const Sample& s = samples[static_cast<std::size_t>(k)];
    Eigen::Matrix<double, 6, 1> row;
    row << 1, s.x, s.y, s.x * s.x, s.x * s.y, s.y * s.y;
    normal += row * row.transpose();
    rhs += row * (s.raw * s.raw);
  }
  return normal.ldlt().solve(rhs);
}

double QuadricResidual(const Eigen::Matrix<double, 6, 1>& q, const Sample& s) {
  Eigen::Matrix<double, 6, 1> row;
  row << 1, s.x, s.y, s.x * s.x, s.x * s.y, s.y * s.y;
  return s.raw - std::sqrt(std::max(0.0, q.dot(row)));
}

// The connected region (8-neighbours on the sampled grid) of the candidate
// cells that holds most of the seed.
std::vector<int> RegionHoldingSeed(const WallMask& grid, const std::vector<Sample>& samples,
                                   const std::vector<int>& candidates, const std::vector<int>& seed) {
  cv::Mat cells(grid.rows, grid.cols, CV_8U, cv::Scalar(0));
  for (const int k : candidates) cells.data[samples[static_cast<std::size_t>(k)].cell] = 1;
  cv::Mat labels;
  const int count = cv::connectedComponents(cells, labels, 8, CV_32S);
  std::vector<int> votes(static_cast<std::size_t>(count), 0);
  for (const int k : seed) {
    const int label = labels.ptr<int>()[samples[static_cast<std::size_t>(k)].cell];
    if (label > 0) ++votes[static_cast<std::size_t>(label)];
  }
  const int chosen = static_cast<int>(std::max_element(votes.begin(), votes.end()) - votes.begin());
  std::vector<int> region;
  if (chosen == 0) return region;
  for (const int k : candidates)
    if (labels.ptr<int>()[samples[static_cast<std::size_t>(k)].cell] == chosen) region.push_back(k);
  return region;
}

// Run lengths of 0s and 1s, starting with 0s (WallMask::RunLengths).
std::vector<int> Runs(const std::vector<std::uint8_t>& cells) {
  std::vector<int> runs;
  std::uint8_t current = 0;
  int length = 0;
  for (const std::uint8_t w : cells) {
    if (w != current) runs.push_back(length), length = 0, current = w;
    ++length;
  }
  runs.push_back(length);
  return runs;
}

}  // namespace

int WallMask::Count() const { return static_cast<int>(std::count(wall.begin(), wall.end(), 1)); }

std::vector<int> WallMask::RunLengths() const { return Runs(wall); }
std::vector<int> WallMask::ReadingRunLengths() const { return Runs(reading); }

StageResult<WallSegmentation> SegmentWall(const WallSegmentationOptions& options, const CameraIntrinsics& depth,
                                          const cv::Mat& raw, const DepthReading& reading, int frame) {
  if (raw.empty()) return Rejection{kCleanupStage, kNoDepthImage};
  WallSegmentation out;
  const std::vector<Sample> samples = SampleGrid(options, depth, raw, reading, out.mask);
  out.sampled_pixels = out.mask.cols * out.mask.rows;
  out.valid_pixels = static_cast<int>(samples.size());
  if (samples.size() < 500) return Rejection{kCleanupStage, "too few valid pixels for a wall"};
  const std::vector<int> seed = DominantPlaneSeed(options, samples, frame);
  if (seed.size() < 30) {
    return Rejection{kCleanupStage, "no plane dominates the image's centre (" + std::to_string(seed.size()) +
                                        " pixels agree): the sensor does not face a wall"};
  }
  std::vector<int> wall = seed;
  for (int round = 0; round < options.grow_rounds; ++round) {
    const auto q = FitQuadric(samples, wall);
    std::vector<double> residual(samples.size()), deviations;
    for (std::size_t k = 0; k < samples.size(); ++k) residual[k] = QuadricResidual(q, samples[k]);
    for (const int k : wall) deviations.push_back(std::abs(residual[static_cast<std::size_t>(k)]));
    out.sigma_raw = 1.4826 * Median(deviations);
    // The first rounds grow with the seed's wide band; later ones keep only
    // what lies within the wall's own scatter.
    const double tolerance = round < 2 ? options.msac_tolerance_raw
                                       : std::max(options.inlier_sigmas * out.sigma_raw, options.min_tolerance_raw);
    std::vector<int> candidates;
    for (std::size_t k = 0; k < samples.size(); ++k)
      if (std::abs(residual[k]) < tolerance) candidates.push_back(static_cast<int>(k));
    std::vector<int> grown = RegionHoldingSeed(out.mask, samples, candidates, seed);
    if (grown.size() < 30) return Rejection{kCleanupStage, "the wall's region fell apart while it was grown"};
    const bool settled = grown == wall;
    wall = std::move(grown);
    if (settled && round >= 2) break;
  }
  for (const int k : wall) {
    const Sample& s = samples[static_cast<std::size_t>(k)];
    out.mask.wall[static_cast<std::size_t>(s.cell)] = 1;
    const int i = s.cell % out.mask.cols, j = s.cell / out.mask.cols;
    out.wall_pixels.push_back({double(options.crop_px + i * options.stride),
                               double(options.crop_px + j * options.stride), s.x, s.y, s.reading});
  }
  return out;
}

bool WallSegmentationOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .AtLeast(crop_px, 0, "crop_px")
      .AtLeast(stride, 1, "stride")
      .Positive(seed_half_width, "seed_half_width")
      .AtLeast(msac_iterations, 1, "msac_iterations")
      .Positive(msac_tolerance_raw, "msac_tolerance_raw")
      .Positive(inlier_sigmas, "inlier_sigmas")
      .AtLeast(min_tolerance_raw, 0, "min_tolerance_raw")
      .AtLeast(grow_rounds, 0, "grow_rounds")
      .valid();
}

}  // namespace speckle
