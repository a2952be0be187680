#include "stages/pairing.h"

#include "schemas/option_check.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace speckle {

namespace {

// The albedo the board shows a depth pixel: its ray met with the board's plane.
double AlbedoSeen(const PairingInput& input, const Eigen::Isometry3d& board_from_depth, const Eigen::Vector3d& normal,
                  double plane_offset, int u, int v) {
  const Eigen::Vector2d xy = input.cameras.depth.Undistort(Eigen::Vector2d(u, v));
  const Eigen::Vector3d ray(xy.x(), xy.y(), 1);
  const double along = normal.dot(ray);
  if (std::abs(along) < 1e-9) return 0.5;
  return BoardAlbedo(input.board_in_depth.board, (board_from_depth * (plane_offset / along * ray)).head<2>());
}

}  // namespace

StageResult<std::vector<PairedSample>> RunPairing(const PairingOptions& options, const PairingInput& input) {
  const cv::Mat& raw = input.raw;
  const Eigen::Isometry3d depth_from_board = input.cameras.depth_from_colour * input.colour_from_board;
  const Eigen::Isometry3d board_from_depth = depth_from_board.inverse();
  const Eigen::Vector3d normal = depth_from_board.linear().col(2);
  const double plane_offset = normal.dot(depth_from_board.translation());
  const double tilt_deg = std::acos(std::min(1.0, std::abs(normal.z()))) * 180 / M_PI;
  const int w = options.window_radius;
  std::vector<PairedSample> samples;
  for (std::size_t index = 0; index < input.board_in_depth.points.size(); ++index) {
    const BoardPoint& point = input.board_in_depth.points[index];
    const int u = static_cast<int>(std::lround(point.pixel.x())), v = static_cast<int>(std::lround(point.pixel.y()));
    if (u - w < 0 || v - w < 0 || u + w >= raw.cols || v + w >= raw.rows) continue;
    // Plane r = c0 + c1 du + c2 dv over the window, du, dv from the point.
    // The albedo goes through the same plane fit as the raw values: a dark
    // square's bias reaches the estimate in the share its pixels have in it,
    // which on a far board's few-pixel squares is far from all or nothing.
    Eigen::Matrix3d normal_matrix = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero(), albedo_rhs = Eigen::Vector3d::Zero();
    bool hole = false;
    for (int dv = -w; dv <= w && !hole; ++dv) {
      for (int du = -w; du <= w; ++du) {
        const std::uint16_t r = raw.at<std::uint16_t>(v + dv, u + du);
        if (!input.reading.IsReading(r)) {
          hole = true;
          break;
        }
        const Eigen::Vector3d row(1, u + du - point.pixel.x(), v + dv - point.pixel.y());
        normal_matrix += row * row.transpose();
        rhs += row * r;
        albedo_rhs += row * AlbedoSeen(input, board_from_depth, normal, plane_offset, u + du, v + dv);
      }
    }
    if (hole) continue;
    const auto solver = normal_matrix.ldlt();
    const Eigen::Vector3d c = solver.solve(rhs);
    double squared = 0;
    for (int dv = -w; dv <= w; ++dv) {
      for (int du = -w; du <= w; ++du) {
        const double model = c(0) + c(1) * (u + du - point.pixel.x()) + c(2) * (v + dv - point.pixel.y());
        squared += std::pow(raw.at<std::uint16_t>(v + dv, u + du) - model, 2);
      }
    }
    if (std::sqrt(squared / ((2 * w + 1) * (2 * w + 1))) >
        options.max_plane_rms_raw * input.reading.UnitsPerRawStep(c(0)))
      continue;
    PairedSample s;
    s.frame = input.frame;
    s.pose = input.pose;
    s.time_s = input.time_s;
    s.u = point.pixel.x();
    s.v = point.pixel.y();
    const Eigen::Vector2d xy = input.cameras.depth.Undistort(point.pixel);
    s.x = xy.x();
    s.y = xy.y();
    s.raw = c(0);
    s.in_colour = input.colour_from_board * point.in_board;
    s.depth_m = (input.cameras.depth_from_colour * s.in_colour).z();
    // z = r . (depth_from_colour applied to q): a rotation w and shift dt of
    // the colour pose move q by w x q + dt, so dz = w . (q x r) + r . dt.
    const Eigen::Vector3d r = input.cameras.depth_from_colour.linear().row(2).transpose();
    Eigen::Matrix<double, 6, 1> dz_dpose;
    dz_dpose << s.in_colour.cross(r), r;
    if (!input.colour_pose_covariance.isZero())
      s.truth_sigma_m = std::sqrt(std::max(0.0, dz_dpose.dot(input.colour_pose_covariance * dz_dpose)));
    s.tilt_deg = tilt_deg;
    s.gradient_u = c(1);
    s.gradient_v = c(2);
    s.albedo = solver.solve(albedo_rhs)(0);
    s.motion_px = input.motion_px;
    s.velocity_u = input.velocity_px_s.x();
    s.velocity_v = input.velocity_px_s.y();
    s.board_point = static_cast<int>(index);
    s.point = point.kind;
    samples.push_back(s);
  }
  if (samples.empty()) return Rejection{"pairing", "no board point had a clean raw value"};
  return samples;
}

bool PairingOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .AtLeast(window_radius, 1, "window_radius")
      .Positive(max_plane_rms_raw, "max_plane_rms_raw")
      .valid();
}

}  // namespace speckle
