#include "simulator/scene_renderer.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "schemas/depth_reading.h"

namespace speckle::sim {
namespace {

constexpr float kDarkAlbedo = 0.1f, kLightAlbedo = 0.9f, kWallAlbedo = 0.7f, kFloorAlbedo = 0.5f;

// A target plane seen from a camera, with the inverse pose precomputed: a
// frame casts millions of rays at it.
struct Plane {
  explicit Plane(const Eigen::Isometry3d& cam_from_target)
      : normal(cam_from_target.linear().col(2)),
        offset(normal.dot(cam_from_target.translation())),
        target_from_cam(cam_from_target.inverse()) {}

  // Distance t along origin + t * direction to the plane (0 when missed or
  // behind), and the hit's target coordinates.
  double Hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, Eigen::Vector2d* uv) const {
    const double denom = normal.dot(direction);
    if (std::abs(denom) < 1e-12) return 0;
    const double t = (offset - normal.dot(origin)) / denom;
    if (t <= 0) return 0;
    *uv = (target_from_cam * (origin + t * direction)).head<2>();
    return t;
  }

  Eigen::Vector3d normal;
  double offset;
  Eigen::Isometry3d target_from_cam;
};

// The same plane seen from the camera's centre, as a homography: a ray
// (x, y, 1) meets it at target coordinates (H ray).head(2) / (H ray).z(),
// in front of the camera where the offset and (H ray).z() = n . ray share a
// sign. One 3 x 3 product per ray instead of a hit and an inverse pose: a
// colour image casts 2.8 million rays.
struct PlaneFromCentre {
  explicit PlaneFromCentre(const Eigen::Isometry3d& cam_from_target) {
    const Eigen::Matrix3d rt = cam_from_target.linear().transpose();
    const Eigen::Vector3d normal = cam_from_target.linear().col(2);
    offset = normal.dot(cam_from_target.translation());
    const Eigen::Vector3d origin = rt * cam_from_target.translation();  // the camera centre is -origin in the target
    h.row(0) = offset * rt.row(0) - origin.x() * normal.transpose();
    h.row(1) = offset * rt.row(1) - origin.y() * normal.transpose();
    h.row(2) = normal.transpose();
  }
  bool Hit(const Eigen::Vector3d& ray, Eigen::Vector2d* uv) const {
    const Eigen::Vector3d p = h * ray;
    if (std::abs(p.z()) < 1e-12 || !(offset * p.z() > 0)) return false;
    *uv = p.head<2>() / p.z();
    return true;
  }
  Eigen::Matrix3d h;
  double offset;
};

// A wall's albedo in grey levels: a faint low-frequency texture, as paint has.
double WallShade(const Eigen::Vector2d& p) {
  return 212 + 6 * std::sin(p.x() * 7.0) * std::cos(p.y() * 5.0) + 3 * std::sin((p.x() + p.y()) * 23.0);
}

// A pixel's rays that hit one wall: their summed shade, from their mean position.
struct WallHits {
  void Add(const Eigen::Vector2d& uv) { sum += uv, ++count; }
  double Shade() const { return count > 0 ? count * WallShade(sum / count) : 0; }
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int count = 0;
};

}  // namespace

SceneRenderer::SceneRenderer(const SensorOptics& optics, const Scenario& scenario,
                             const std::vector<const SimEffect*>& effects)
    : optics_(optics), scenario_(scenario), effects_(effects) {
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();
  for (const SimEffect* e : effects_) shift += e->DepthGridShift();
  const cv::Size size = optics.ir.size;
  depth_rays_.resize(static_cast<std::size_t>(size.area()));
  tbb::parallel_for(0, size.height, [&](int v) {
    for (int u = 0; u < size.width; ++u)
      depth_rays_[static_cast<std::size_t>(v) * size.width + u] = optics.ir.Undistort(Eigen::Vector2d(u, v) + shift);
  });
  colour_rays_ = optics.colour.PixelRays(kSamples);
}

Eigen::Isometry3d IrFromBackground(const RigSpec& rig, const TargetPose& board) {
  Eigen::Isometry3d ir_from_background = Eigen::Isometry3d::Identity();
  ir_from_background.linear() = (Eigen::AngleAxisd(rig.background_tilt_deg[0] * M_PI / 180, Eigen::Vector3d::UnitX()) *
                                 Eigen::AngleAxisd(rig.background_tilt_deg[1] * M_PI / 180, Eigen::Vector3d::UnitY()))
                                    .toRotationMatrix();
  if (rig.background_behind_board_m > 0) {
    const Eigen::Vector3d centre = board.ir_from_target * Eigen::Vector3d(rig.squares_x * rig.square_size_m / 2,
                                                                          rig.squares_y * rig.square_size_m / 2, 0);
    ir_from_background.translation() = centre + Eigen::Vector3d(0, 0, rig.background_behind_board_m);
  } else {
    ir_from_background.translation().z() = rig.background_depth_m;
  }
  return ir_from_background;
}

DepthTruth SceneRenderer::TrueDepth(const TargetPose& pose, const std::vector<Clutter>& clutter) const {
  const cv::Size size = optics_.ir.size;
  DepthTruth truth{cv::Mat(size, CV_64FC1, cv::Scalar(0)), cv::Mat(size, CV_32FC1, cv::Scalar(kWallAlbedo)),
                   cv::Mat(size, CV_8UC1, cv::Scalar(static_cast<int>(Surface::kNone)))};
  const double width = scenario_.rig.squares_x * scenario_.rig.square_size_m;
  const double height = scenario_.rig.squares_y * scenario_.rig.square_size_m;
  const double square = scenario_.rig.square_size_m;
  const Plane target(pose.ir_from_target), background(IrFromBackground(scenario_.rig, pose));
  const Eigen::Vector3d projector = optics_.projector_in_ir;
  const auto on_board = [&](const Eigen::Vector2d& uv) {
    return uv.x() >= 0 && uv.x() <= width && uv.y() >= 0 && uv.y() <= height;
  };
  // The nearest object covering the pixel, if any.
  const auto clutter_at = [&](int u, int v) {
    double z = 0;
    for (const Clutter& c : clutter)
      if (c.region.contains({u, v}) && (z == 0 || c.z_m < z)) z = c.z_m;
    return z;
  };
  tbb::parallel_for(0, size.height, [&](int v) {
    auto* z_row = truth.z_m.ptr<double>(v);
    auto* albedo_row = truth.albedo.ptr<float>(v);
    auto* surface_row = truth.surface.ptr<std::uint8_t>(v);
    for (int u = 0; u < size.width; ++u) {
      if (const double z_clutter = clutter_at(u, v); z_clutter > 0) {
        z_row[u] = z_clutter;
        surface_row[u] = static_cast<std::uint8_t>(Surface::kClutter);
        continue;
      }
      const Eigen::Vector2d& xy = DepthRay(u, v);
      const Eigen::Vector3d ray(xy.x(), xy.y(), 1.0);
      Eigen::Vector2d uv;
      double z = target.Hit(Eigen::Vector3d::Zero(), ray, &uv);
      bool board_hit = false;
      Surface surface = Surface::kTarget;
      if (pose.is_board) {
        board_hit = z > 0 && on_board(uv);
        if (!board_hit) {
          z = background.Hit(Eigen::Vector3d::Zero(), ray, &uv);
          surface = Surface::kBackground;
        }
      }
      float albedo = kWallAlbedo;
      if (board_hit) {
        const int i = static_cast<int>(std::floor(uv.x() / square)), j = static_cast<int>(std::floor(uv.y() / square));
        albedo = (i + j) % 2 == 0 ? kDarkAlbedo : kLightAlbedo;
      }
      // The room: floor below (y > 0 is down) and ceiling above, in front of the wall.
      if (!board_hit && xy.y() != 0) {
        const double plane_y = xy.y() > 0 ? scenario_.room.floor_below_m : -scenario_.room.ceiling_above_m;
        const double z_room = plane_y / xy.y();
        if (z_room > 0 && (z <= 0 || z_room < z)) {
          z = z_room;
          albedo = kFloorAlbedo;
          surface = Surface::kRoom;
        }
      }
      // Projector shadow: the board hides this point from the speckle projector.
      if (pose.is_board && !board_hit && z > 0) {
        const Eigen::Vector3d point = z * ray;
        Eigen::Vector2d shadow_uv;
        const double t = target.Hit(projector, point - projector, &shadow_uv);
        if (t > 0 && t < 1 && on_board(shadow_uv)) z = 0;
      }
      z_row[u] = z;
      albedo_row[u] = albedo;
      surface_row[u] = static_cast<std::uint8_t>(z > 0 ? surface : Surface::kNone);
    }
  });
  return truth;
}

cv::Mat SceneRenderer::RawFromDepth(const DepthTruth& truth, const FrameContext& frame, std::mt19937_64& rng) const {
  const DepthFormation& f = scenario_.depth;
  const std::uint16_t none =
      DepthReading(f.millimetre ? DepthUnits::kMillimetre : DepthUnits::kRaw11Bit).NoReadingValue();
  cv::Mat raw(truth.z_m.size(), CV_16UC1);
  // One noise stream per row, seeded from the frame's: deterministic in any
  // thread schedule. OpenCV's generator (a multiply-with-carry and a ziggurat
  // for the normal) draws a pixel's noise in a few nanoseconds, where
  // std::normal_distribution over mt19937_64 took a fifth of a session's
  // simulation.
  const std::uint64_t frame_seed = rng();
  tbb::parallel_for(0, raw.rows, [&](int v) {
    cv::RNG row_rng(frame_seed + 0x9e3779b97f4a7c15ULL * static_cast<std::uint64_t>(v + 1));
    const auto* z = truth.z_m.ptr<double>(v);
    const auto* albedo = truth.albedo.ptr<float>(v);
    auto* out = raw.ptr<std::uint16_t>(v);
    for (int u = 0; u < raw.cols; ++u) {
      const double n =
          row_rng.gaussian(f.raw_noise_sigma);  // drawn for every pixel so noise does not depend on the scene
      const Eigen::Vector2d& xy = DepthRay(u, v);
      if (z[u] < f.min_depth_m || !(xy.norm() <= optics_.usable_radius)) {  // NaN rays too
        out[u] = none;
        continue;
      }
      DepthSample sample{u, v, xy.x(), xy.y(), z[u], f.RawFromDepth(z[u]), albedo[u], frame.time_s};
      double r = sample.raw;
      for (const SimEffect* e : effects_) r += e->RawOffset(sample);
      // The sensor reports whole raw units (1/8-pixel disparity steps).
      r = std::round(r + n);
      if (r > f.max_raw || r < 0) {
        out[u] = none;
      } else if (f.millimetre) {  // the OpenNI driver's conversion of the raw value it got
        const double mm = std::round(1000 * (f.DepthFromRaw(r) - f.mm_offset_m) / f.mm_gain);
        out[u] = (mm >= 1 && mm <= 65535) ? static_cast<std::uint16_t>(mm) : none;
      } else {
        out[u] = static_cast<std::uint16_t>(r);
      }
    }
  });
  return raw;
}

cv::Mat SceneRenderer::CleanGrey(const TargetPose& pose, const CameraModel& camera,
                                 const std::vector<Eigen::Vector2d>& rays, const Eigen::Isometry3d& cam_from_ir) const {
  const int s = kSamples;
  const cv::Size size = camera.size;
  const Eigen::Isometry3d cam_from_target = cam_from_ir * pose.ir_from_target;
  const PlaneFromCentre target(cam_from_target), wall(cam_from_ir * IrFromBackground(scenario_.rig, pose));
  const int nx = scenario_.rig.squares_x, ny = scenario_.rig.squares_y;
  const double square = scenario_.rig.square_size_m;
  cv::Mat grey(size, CV_32FC1);
  tbb::parallel_for(0, size.height, [&](int v) {
    auto* row = grey.ptr<float>(v);
    for (int u = 0; u < size.width; ++u) {
      // The wall's texture varies over tens of centimetres, a pixel's
      // footprint over millimetres: it is shaded once, at the mean of the
      // pixel's wall hits (the per-ray sines were 60 % of a session's
      // rendering), for the target plane's and the background's hits apart.
      double sum = 0;
      WallHits on_target, on_background;
      for (int sy = 0; sy < s; ++sy) {
        for (int sx = 0; sx < s; ++sx) {
          const auto& xy = rays[static_cast<std::size_t>(v * s + sy) * size.width * s + u * s + sx];
          const Eigen::Vector3d ray(xy.x(), xy.y(), 1.0);
          Eigen::Vector2d uv;
          if (target.Hit(ray, &uv)) {
            const int i = static_cast<int>(std::floor(uv.x() / square));
            const int j = static_cast<int>(std::floor(uv.y() / square));
            if (!pose.is_board) {
              on_target.Add(uv);
            } else if (i >= 0 && i < nx && j >= 0 && j < ny) {
              sum += (i + j) % 2 == 0 ? 25 : 235;
            } else if (wall.Hit(ray, &uv)) {
              on_background.Add(uv);
            }
          } else if (wall.Hit(ray, &uv)) {
            on_background.Add(uv);
          }
        }
      }
      sum += on_target.Shade() + on_background.Shade();
      row[u] = static_cast<float>(sum / (s * s));
    }
  });
  cv::GaussianBlur(grey, grey, cv::Size(0, 0), 0.7);  // the lens
  return grey;
}

cv::Mat SceneRenderer::WithSensorNoise(const cv::Mat& clean_grey, std::mt19937_64& rng) const {
  cv::Mat noise(clean_grey.size(), CV_32FC1);
  cv::RNG cv_rng(rng());
  cv_rng.fill(noise, cv::RNG::NORMAL, 0, scenario_.colour_noise_sigma);
  return clean_grey + noise;
}

cv::Mat SceneRenderer::CleanColour(const TargetPose& pose) const {
  return CleanGrey(pose, optics_.colour, colour_rays_, optics_.colour_from_ir);
}

cv::Mat SceneRenderer::CleanInfrared(const TargetPose& pose) const {
  std::call_once(ir_rays_once_, [this] { ir_rays_ = optics_.ir.PixelRays(kSamples); });
  return CleanGrey(pose, optics_.ir, ir_rays_, Eigen::Isometry3d::Identity());
}

cv::Mat SceneRenderer::Colour(const cv::Mat& clean_grey, std::mt19937_64& rng) const {
  cv::Mat grey8, rgb;
  WithSensorNoise(clean_grey, rng).convertTo(grey8, CV_8U);
  cv::cvtColor(grey8, rgb, cv::COLOR_GRAY2RGB);
  return rgb;
}

cv::Mat SceneRenderer::Infrared(const cv::Mat& clean_grey, std::mt19937_64& rng) const {
  // IR images for intrinsics are taken with the projector covered and an IR
  // lamp on: the same board, seen by the IR camera, 10-bit.
  cv::Mat ir;
  WithSensorNoise(clean_grey, rng).convertTo(ir, CV_16U, 4.0);
  return ir;
}

}  // namespace speckle::sim
