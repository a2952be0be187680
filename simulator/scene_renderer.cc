#include "simulator/scene_renderer.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace speckle::sim {
namespace {

struct PlaneHit {
  double lambda = 0;  // distance along the ray (z for rays with z = 1)
  Eigen::Vector2d uv; // target coordinates of the hit
};

// Intersects the ray t*(x, y, 1) from a camera at the origin with the target plane.
bool HitTarget(const Eigen::Isometry3d& cam_from_target, const Eigen::Vector3d& ray, PlaneHit* hit) {
  const Eigen::Vector3d normal = cam_from_target.linear().col(2);
  const double denom = normal.dot(ray);
  if (std::abs(denom) < 1e-12) return false;
  const double lambda = normal.dot(cam_from_target.translation()) / denom;
  if (lambda <= 0) return false;
  const Eigen::Vector3d local = cam_from_target.inverse() * (lambda * ray);
  *hit = {lambda, local.head<2>()};
  return true;
}

// A wall's albedo: smooth low-contrast texture so it is not uniform.
double WallShade(const Eigen::Vector2d& p) {
  return 212 + 6 * std::sin(p.x() * 7.0) * std::cos(p.y() * 5.0) + 3 * std::sin((p.x() + p.y()) * 23.0);
}

}  // namespace

SceneRenderer::SceneRenderer(const SensorOptics& optics, const Scenario& scenario)
    : optics_(optics), scenario_(scenario), ir_rays_(optics.ir.PixelRays(1)),
      colour_rays_(optics.colour.PixelRays(colour_samples_)) {}

cv::Mat SceneRenderer::TrueDepth(const TargetPose& pose) const {
  const cv::Size size = optics_.ir.size;
  cv::Mat depth(size, CV_64FC1, cv::Scalar(0));
  const double width = scenario_.rig.squares_x * scenario_.rig.square_size_m;
  const double height = scenario_.rig.squares_y * scenario_.rig.square_size_m;
  tbb::parallel_for(0, size.height, [&](int v) {
    auto* row = depth.ptr<double>(v);
    for (int u = 0; u < size.width; ++u) {
      const Eigen::Vector2d& xy = ir_rays_[static_cast<std::size_t>(v) * size.width + u];
      const Eigen::Vector3d ray(xy.x(), xy.y(), 1.0);
      PlaneHit hit;
      const bool on_target = HitTarget(pose.ir_from_target, ray, &hit) &&
                             (!pose.is_board || (hit.uv.x() >= 0 && hit.uv.x() <= width && hit.uv.y() >= 0 &&
                                                 hit.uv.y() <= height));
      if (on_target) {
        row[u] = hit.lambda;
      } else if (pose.is_board) {
        row[u] = scenario_.rig.background_depth_m;  // the wall behind the board
      }
    }
  });
  return depth;
}

cv::Mat SceneRenderer::RawFromDepth(const cv::Mat& true_depth_m, std::mt19937_64& rng) const {
  const DepthFormation& f = scenario_.depth;
  cv::Mat raw(true_depth_m.size(), CV_16UC1);
  std::normal_distribution<double> noise(0.0, f.raw_noise_sigma);
  for (int v = 0; v < raw.rows; ++v) {
    const auto* z = true_depth_m.ptr<double>(v);
    auto* out = raw.ptr<std::uint16_t>(v);
    for (int u = 0; u < raw.cols; ++u) {
      const Eigen::Vector2d& xy = ir_rays_[static_cast<std::size_t>(v) * raw.cols + u];
      const bool lost = xy.norm() > optics_.usable_radius;
      if (z[u] < f.min_depth_m || lost) {
        out[u] = 2047;
        continue;
      }
      // Inverse of z = 1 / (a r + b); the sensor reports whole raw units.
      const double r = std::round((1.0 / z[u] - f.b) / f.a + noise(rng));
      out[u] = (r > f.max_raw || r < 0) ? 2047 : static_cast<std::uint16_t>(r);
    }
  }
  return raw;
}

cv::Mat SceneRenderer::Colour(const TargetPose& pose, std::mt19937_64& rng) const {
  const int s = colour_samples_;
  const cv::Size size = optics_.colour.size;
  const Eigen::Isometry3d colour_from_target = optics_.colour_from_ir * pose.ir_from_target;
  // The background wall, fronto-parallel to the IR camera, seen from the colour camera.
  Eigen::Isometry3d ir_from_wall = Eigen::Isometry3d::Identity();
  ir_from_wall.translation().z() = scenario_.rig.background_depth_m;
  const Eigen::Isometry3d colour_from_wall = optics_.colour_from_ir * ir_from_wall;
  const int nx = scenario_.rig.squares_x, ny = scenario_.rig.squares_y;
  const double square = scenario_.rig.square_size_m;
  cv::Mat grey(size, CV_32FC1);
  tbb::parallel_for(0, size.height, [&](int v) {
    auto* row = grey.ptr<float>(v);
    for (int u = 0; u < size.width; ++u) {
      double sum = 0;
      for (int sy = 0; sy < s; ++sy) {
        for (int sx = 0; sx < s; ++sx) {
          const auto& xy = colour_rays_[static_cast<std::size_t>(v * s + sy) * size.width * s + u * s + sx];
          const Eigen::Vector3d ray(xy.x(), xy.y(), 1.0);
          PlaneHit hit;
          double shade = 0;
          if (HitTarget(colour_from_target, ray, &hit)) {
            const int i = static_cast<int>(std::floor(hit.uv.x() / square));
            const int j = static_cast<int>(std::floor(hit.uv.y() / square));
            if (!pose.is_board) {
              shade = WallShade(hit.uv);
            } else if (i >= 0 && i < nx && j >= 0 && j < ny) {
              shade = (i + j) % 2 == 0 ? 25 : 235;
            } else if (HitTarget(colour_from_wall, ray, &hit)) {
              shade = WallShade(hit.uv);
            }
          } else if (HitTarget(colour_from_wall, ray, &hit)) {
            shade = WallShade(hit.uv);
          }
          sum += shade;
        }
      }
      row[u] = static_cast<float>(sum / (s * s));
    }
  });
  // Lens blur, then sensor noise.
  cv::GaussianBlur(grey, grey, cv::Size(0, 0), 0.7);
  cv::Mat noise(size, CV_32FC1);
  cv::RNG cv_rng(rng());
  cv_rng.fill(noise, cv::RNG::NORMAL, 0, scenario_.colour_noise_sigma);
  grey += noise;
  cv::Mat grey8, rgb;
  grey.convertTo(grey8, CV_8U);
  cv::cvtColor(grey8, rgb, cv::COLOR_GRAY2RGB);
  return rgb;
}

}  // namespace speckle::sim
