#include "stages/pairing.h"

#include <algorithm>
#include <cmath>

namespace speckle {

StageResult<std::vector<PairedSample>> RunPairing(const PairingOptions& options, const PairingInput& input) {
  const cv::Mat& raw = input.raw;
  const Eigen::Isometry3d depth_from_board = input.cameras.depth_from_colour * input.colour_from_board;
  const Eigen::Vector3d normal = depth_from_board.linear().col(2);
  const double tilt_deg = std::acos(std::min(1.0, std::abs(normal.z()))) * 180 / M_PI;
  const int w = options.window_radius;
  std::vector<PairedSample> samples;
  std::vector<std::uint16_t> window;
  for (const BoardPoint& point : input.board_in_depth.points) {
    const int u = static_cast<int>(std::lround(point.pixel.x())), v = static_cast<int>(std::lround(point.pixel.y()));
    if (u - w - 1 < 0 || v - w - 1 < 0 || u + w + 1 >= raw.cols || v + w + 1 >= raw.rows) continue;
    window.clear();
    for (int dv = -w; dv <= w; ++dv)
      for (int du = -w; du <= w; ++du) window.push_back(raw.at<std::uint16_t>(v + dv, u + du));
    const auto [lo, hi] = std::minmax_element(window.begin(), window.end());
    if (*hi == 2047 || *hi - *lo > options.max_window_spread_raw) continue;
    std::nth_element(window.begin(), window.begin() + static_cast<std::ptrdiff_t>(window.size() / 2), window.end());
    const double gx = (raw.at<std::uint16_t>(v, u + 1) - raw.at<std::uint16_t>(v, u - 1)) / 2.0;
    const double gy = (raw.at<std::uint16_t>(v + 1, u) - raw.at<std::uint16_t>(v - 1, u)) / 2.0;
    PairedSample s;
    s.frame = input.frame;
    s.pose = input.pose;
    s.time_s = input.time_s;
    s.u = point.pixel.x();
    s.v = point.pixel.y();
    const Eigen::Vector2d xy = input.cameras.depth.Undistort(point.pixel);
    s.x = xy.x();
    s.y = xy.y();
    s.raw = window[window.size() / 2];
    s.depth_m = (depth_from_board * point.in_board).z();
    s.tilt_deg = tilt_deg;
    s.gradient = std::hypot(gx, gy);
    s.albedo = point.albedo;
    s.motion_px = input.motion_px;
    s.point = point.kind;
    samples.push_back(s);
  }
  if (samples.empty()) return Rejection{"pairing", "no board point had a clean raw value"};
  return samples;
}

}  // namespace speckle
