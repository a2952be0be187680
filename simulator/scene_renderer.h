#pragma once
// Renders what the Kinect sees of one target (a chessboard proud of a wall,
// or a bare wall): raw depth by ray casting through the IR camera, colour by
// supersampled ray casting through the colour camera.
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <random>

#include "simulator/optics_presets.h"
#include "simulator/scenario.h"

namespace speckle::sim {

struct TargetPose {
  // Target coordinates -> IR camera coordinates (metres). The target is the
  // plane z = 0; a board occupies [0, width] x [0, height] of it.
  Eigen::Isometry3d ir_from_target = Eigen::Isometry3d::Identity();
  bool is_board = true;  // false: an unbounded wall filling the view
};

class SceneRenderer {
 public:
  SceneRenderer(const SensorOptics& optics, const Scenario& scenario);

  // True depth (z along the IR axis, metres) of every IR pixel; 0 = nothing hit.
  cv::Mat TrueDepth(const TargetPose& pose) const;
  // Raw 11-bit values from true depth: inverse base form, noise, rounding,
  // 2047 where the sensor has no reading.
  cv::Mat RawFromDepth(const cv::Mat& true_depth_m, std::mt19937_64& rng) const;
  cv::Mat Colour(const TargetPose& pose, std::mt19937_64& rng) const;  // CV_8UC3, RGB

  const SensorOptics& optics() const { return optics_; }

 private:
  SensorOptics optics_;
  Scenario scenario_;
  std::vector<Eigen::Vector2d> ir_rays_;
  std::vector<Eigen::Vector2d> colour_rays_;  // supersampled
  static constexpr int colour_samples_ = 3;  // per axis: 9 rays per colour pixel
};

}  // namespace speckle::sim
