#pragma once
// Renders what the Kinect sees of one target (a chessboard proud of a wall,
// or a bare wall) in a room with a floor and a ceiling: raw depth by ray
// casting through the IR camera, colour and IR intensity by supersampled ray
// casting.
#include <Eigen/Geometry>
#include <mutex>
#include <opencv2/core.hpp>
#include <random>

#include "simulator/optics_presets.h"
#include "simulator/scenario.h"
#include "simulator/sim_effect.h"

namespace speckle::sim {

// What surface a depth pixel's ray hits first.
enum class Surface : std::uint8_t {
  kNone = 0,        // nothing, or the projector's shadow
  kTarget = 1,      // the board, or the wall of a planar snapshot
  kBackground = 2,  // the wall behind a board
  kRoom = 3,        // floor or ceiling
  kClutter = 4,     // an object in front of the target
};

// What each depth pixel's ray hits.
struct DepthTruth {
  cv::Mat z_m;      // CV_64F true depth along the IR axis; 0 = no reading (shadow, nothing hit)
  cv::Mat albedo;   // CV_32F IR reflectivity of the surface hit
  cv::Mat surface;  // CV_8U Surface of each pixel: a planar snapshot's true wall mask is kTarget
};

// Where the wall behind a board stands (IR from wall): at
// rig.background_depth_m, or rig.background_behind_board_m behind the
// board's centre; tilted by rig.background_tilt_deg either way.
Eigen::Isometry3d IrFromBackground(const RigSpec& rig, const TargetPose& board);

// An object near the sensor (inside the minimum range), as a pixel rectangle.
struct Clutter {
  cv::Rect region;
  double z_m = 0.3;
};

class SceneRenderer {
 public:
  // `effects` must outlive the renderer.
  SceneRenderer(const SensorOptics& optics, const Scenario& scenario, const std::vector<const SimEffect*>& effects);

  DepthTruth TrueDepth(const TargetPose& depth_pose, const std::vector<Clutter>& clutter) const;
  // Raw 11-bit values: inverse base form, effects, noise, rounding; 2047
  // where the sensor has no reading. A millimetre scenario reports each raw
  // value through the driver's conversion instead, 0 where there is none.
  cv::Mat RawFromDepth(const DepthTruth& truth, const FrameContext& frame, std::mt19937_64& rng) const;
  // What the colour (or IR) camera sees of a still target before sensor
  // noise: grey levels 0..255 after the lens blur. Every frame of a still
  // pose shares it, so a session renders it once per pose.
  cv::Mat CleanColour(const TargetPose& pose) const;
  cv::Mat CleanInfrared(const TargetPose& pose) const;
  // A frame's picture: the clean one with this frame's sensor noise.
  cv::Mat Colour(const cv::Mat& clean_grey, std::mt19937_64& rng) const;    // CV_8UC3 RGB
  cv::Mat Infrared(const cv::Mat& clean_grey, std::mt19937_64& rng) const;  // CV_16UC1, 10-bit

  const SensorOptics& optics() const { return optics_; }
  // Normalized undistorted coordinates of the ray behind depth pixel (u, v).
  const Eigen::Vector2d& DepthRay(int u, int v) const {
    return depth_rays_[static_cast<std::size_t>(v) * optics_.ir.size.width + u];
  }

 private:
  // Grey levels 0..255 seen by a camera `cam_from_ir` away from the IR camera, blurred by its lens.
  cv::Mat CleanGrey(const TargetPose& pose, const CameraModel& camera, const std::vector<Eigen::Vector2d>& rays,
                    const Eigen::Isometry3d& cam_from_ir) const;
  cv::Mat WithSensorNoise(const cv::Mat& clean_grey, std::mt19937_64& rng) const;

  SensorOptics optics_;
  Scenario scenario_;
  std::vector<const SimEffect*> effects_;
  std::vector<Eigen::Vector2d> depth_rays_;       // IR rays, shifted by any depth grid offset
  std::vector<Eigen::Vector2d> colour_rays_;      // supersampled
  mutable std::vector<Eigen::Vector2d> ir_rays_;  // supersampled, on first use: most sessions have no IR images
  mutable std::once_flag ir_rays_once_;
  static constexpr int kSamples = 3;  // per axis: 9 rays per grey pixel
};

}  // namespace speckle::sim
