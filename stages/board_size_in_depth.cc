#include "stages/board_size_in_depth.h"

#include <algorithm>
#include <cmath>

#include "model/sensor_family.h"

namespace speckle {
namespace {

// One view on the line raw = c - slope * x.
struct LinePoint {
  double x = 0;    // PointOf's, in pixels of the 640-wide disparity image per metre of the rig's units
  double raw = 0;  // the board's median raw value
  Eigen::Vector3d pose = Eigen::Vector3d::Zero();  // the board's origin in the depth camera
};

struct Line {
  double c = 0, slope = 0;
};

// Each view's still pose: views whose boards sit within a centimetre of
// each other's. Returns the pose of each view, numbered from 0.
std::vector<int> StillPoses(const std::vector<LinePoint>& points) {
  std::vector<Eigen::Vector3d> poses;
  std::vector<int> pose_of;
  for (const auto& p : points) {
    const auto same =
        std::find_if(poses.begin(), poses.end(), [&](const auto& q) { return (q - p.pose).norm() < 0.01; });
    pose_of.push_back(static_cast<int>(same - poses.begin()));
    if (same == poses.end()) poses.push_back(p.pose);
  }
  return pose_of;
}

double QuadAreaPx(const DepthboardQuad& quad) {
  double twice = 0;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d& a = quad.corners_px[i];
    const Eigen::Vector2d& b = quad.corners_px[(i + 1) % 4];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return std::abs(twice) / 2;
}

// The board's corners in the undistorted depth image: the lens would make a
// board's area depend on where in the image it is.
double UndistortedAreaPx(const DepthboardQuad& quad, const CameraIntrinsics& depth) {
  DepthboardQuad undistorted = quad;
  const cv::Matx33d& k = depth.camera_matrix;
  for (auto& corner : undistorted.corners_px) {
    const Eigen::Vector2d xy = depth.Undistort(corner);
    corner = Eigen::Vector2d(k(0, 0) * xy.x() + k(0, 2), k(1, 1) * xy.y() + k(1, 2));
  }
  return QuadAreaPx(undistorted);
}

// With the board in the depth camera (the rig's units), its pixel area is
// fx^2 d I3 and the median raw reads c - 8 fx B I4 / I3, d the plane's
// distance and Ik the board's integral of z^-k: x = sqrt(area / (d I3)) I4 / I3
// is then fx / z for a board facing the camera, and exact for a tilted one.
std::optional<LinePoint> PointOf(const BoardGeometry& board, const Eigen::Isometry3d& depth_from_board,
                                 double area_px) {
  constexpr int kSteps = 12;
  double i3 = 0, i4 = 0;
  for (int a = 0; a < kSteps; ++a)
    for (int b = 0; b < kSteps; ++b) {
      const Eigen::Vector3d p(board.Width() * (a + 0.5) / kSteps, board.Height() * (b + 0.5) / kSteps, 0);
      const double z = (depth_from_board * p).z();
      if (!(z > 0)) return std::nullopt;
      i3 += std::pow(z, -3), i4 += std::pow(z, -4);
    }
  const double cell = board.Width() * board.Height() / (kSteps * kSteps);
  i3 *= cell, i4 *= cell;
  const double d = std::abs(depth_from_board.linear().col(2).dot(depth_from_board.translation()));
  // A board seen nearly edge-on has an area made of its outline's pixels alone.
  if (!(d * i3 > 0.3 * board.Width() * board.Height() * std::pow(i4 / i3, 2)) || !(area_px > 0)) return std::nullopt;
  return LinePoint{std::sqrt(area_px / (d * i3)) * i4 / i3, 0};
}

Line FitLine(const std::vector<LinePoint>& points) {
  const double n = static_cast<double>(points.size());
  double mx = 0, mr = 0;
  for (const auto& p : points) mx += p.x / n, mr += p.raw / n;
  double sxx = 0, sxr = 0;
  for (const auto& p : points) sxx += (p.x - mx) * (p.x - mx), sxr += (p.x - mx) * (p.raw - mr);
  Line line;
  line.slope = -sxr / sxx;
  line.c = mr + line.slope * mx;
  return line;
}

// The views a robust scale of the residuals keeps: a quad that took in a
// hand or a neighbouring surface is off the line by far more than the rest.
std::vector<LinePoint> WithoutOutliers(const std::vector<LinePoint>& points, const Line& line) {
  std::vector<double> residuals;
  for (const auto& p : points) residuals.push_back(std::abs(p.raw - (line.c - line.slope * p.x)));
  std::vector<double> sorted = residuals;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double scale = 1.4826 * sorted[sorted.size() / 2];
  std::vector<LinePoint> kept;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!(scale > 0) || residuals[i] <= 4 * scale) kept.push_back(points[i]);
  return kept;
}

// The slope's sigma by leaving one still pose out at a time: frames of one
// pose share its geometry (its outline's and its raw median's errors), so
// the line has as many independent views as poses, and their scatter, not
// the frames', says how well it is known.
double SlopeSigmaByPose(const std::vector<LinePoint>& points) {
  const std::vector<int> pose_of = StillPoses(points);
  const int poses = *std::max_element(pose_of.begin(), pose_of.end()) + 1;
  std::vector<double> slopes;
  for (int left_out = 0; left_out < poses; ++left_out) {
    std::vector<LinePoint> rest;
    for (std::size_t i = 0; i < points.size(); ++i)
      if (pose_of[i] != left_out) rest.push_back(points[i]);
    slopes.push_back(FitLine(rest).slope);
  }
  double mean = 0, sum = 0;
  for (const double slope : slopes) mean += slope / poses;
  for (const double slope : slopes) sum += (slope - mean) * (slope - mean);
  return std::sqrt((poses - 1.0) / poses * sum);
}

}  // namespace

bool BoardSizeInDepth::OutsideFamily() const {
  const double ratio = Ratio(), sigma = sigma_m / stated_m;
  // Measured with the family's baseline B0, a correctly described board
  // reads B0 / B of its size, B the sensor's own baseline.
  return ratio - 3 * sigma > model::kFamilyBaselineM / model::kMinMeasuredBaselineM ||
         ratio + 3 * sigma < model::kFamilyBaselineM / model::kMaxMeasuredBaselineM;
}

std::optional<BoardSizeInDepth> MeasureBoardSizeInDepth(const BoardSizeOptions& options, const BoardGeometry& board,
                                                        const std::vector<ExtrinsicsView>& views,
                                                        const CameraIntrinsics& depth,
                                                        const Eigen::Isometry3d& depth_from_colour) {
  if (!(depth.image_size.width > 0) || !(board.Width() > 0) || !(board.Height() > 0)) return std::nullopt;
  const double to_disparity_px = model::kDisparityImageWidth / depth.image_size.width;
  std::vector<LinePoint> points;
  for (const auto& view : views) {
    const double area = UndistortedAreaPx(view.quad, depth) * to_disparity_px * to_disparity_px;
    auto p = PointOf(board, depth_from_colour * view.colour_from_board, area);
    if (!p || !(view.quad.board_raw_median > 0)) continue;
    p->raw = view.quad.board_raw_median;
    p->pose = (depth_from_colour * view.colour_from_board).translation();
    points.push_back(*p);
  }
  const auto too_few = [&] {
    const std::vector<int> pose_of = StillPoses(points);
    return pose_of.empty() || *std::max_element(pose_of.begin(), pose_of.end()) + 1 < options.min_poses;
  };
  if (too_few()) return std::nullopt;
  points = WithoutOutliers(points, FitLine(points));
  const auto [lowest, highest] =
      std::minmax_element(points.begin(), points.end(), [](const auto& a, const auto& b) { return a.raw < b.raw; });
  if (too_few() || highest->raw - lowest->raw < options.min_raw_span) return std::nullopt;
  const Line line = FitLine(points);
  if (!(line.slope > 0)) return std::nullopt;
  BoardSizeInDepth out;
  out.stated_m = std::sqrt(board.Width() * board.Height());
  out.measured_m = out.stated_m * 8 * model::kFamilyBaselineM / line.slope;
  out.sigma_m = out.measured_m * SlopeSigmaByPose(points) / line.slope;
  if (!std::isfinite(out.sigma_m)) return std::nullopt;  // every pose but one at one distance
  out.views = static_cast<int>(points.size());
  return out;
}

}  // namespace speckle
