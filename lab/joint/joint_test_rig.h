#pragma once
// A known rig for the joint calibration's tests: two cameras, their
// extrinsics and a reciprocal depth model; a session of board poses seen by
// both, with pixel and raw noise; and a start where a user's separate steps
// leave the cameras.
#include <array>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "lab/joint/joint_calibration.h"
#include "lab/joint/joint_residuals.h"
#include "stages/outline_calibration.h"

namespace speckle::joint::testing {

// A rig, its boards and what each camera sees of them.
struct Rig {
  CameraIntrinsics colour, depth;
  Eigen::Isometry3d depth_from_colour = Eigen::Isometry3d::Identity();
  std::vector<double> base = {-0.0030, 3.3};  // reciprocal: z = 1 / (a raw + b)
  BoardGeometry board{9, 7, 0.04};
  // A reference_tilt the model may lack: raw += tilt[0] x + tilt[1] y.
  std::array<double, 2> tilt = {0, 0};
};

inline CameraIntrinsics Camera(double fx, double fy, double cx, double cy, std::array<double, 5> lens) {
  CameraIntrinsics c;
  c.image_size = {640, 480};
  c.camera_matrix = cv::Matx33d(fx, 0, cx, 0, fy, cy, 0, 0, 1);
  c.distortion = lens;
  return c;
}

inline Eigen::Vector2d Projected(const CameraIntrinsics& c, const Eigen::Vector3d& q) {
  double k[4], lens[5], pixel[2];
  const cv::Matx33d& m = c.camera_matrix;
  k[0] = m(0, 0), k[1] = m(1, 1), k[2] = m(0, 2), k[3] = m(1, 2);
  std::copy(c.distortion.begin(), c.distortion.end(), lens);
  Project(k, lens, q.data(), pixel);
  return {pixel[0], pixel[1]};
}

struct Observations {
  std::vector<BoardFrame> frames;
  std::vector<PairedSample> samples;
  std::vector<double> true_depths;
};

inline Observations Observe(const Rig& rig, int poses, std::mt19937& rng) {
  std::normal_distribution<double> pixel_noise(0, 0.1), raw_noise(0, 0.3);
  std::uniform_real_distribution<double> depth(0.7, 2.6), tilt(-0.5, 0.5), lateral(-0.25, 0.25);
  Observations out;
  const auto outline = OutlineCorners(rig.board);
  for (int f = 0; f < poses; ++f) {
    BoardFrame frame;
    frame.frame = f, frame.pose = f;
    const double z = depth(rng);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    // Each draw its own statement: arguments are evaluated in an order the
    // compiler chooses (GCC and clang differ), and the sanitizer build drew
    // other noise from the same seed.
    const double tilt_x = tilt(rng), tilt_y = tilt(rng);
    pose.linear() =
        (Eigen::AngleAxisd(tilt_x, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(tilt_y, Eigen::Vector3d::UnitY()))
            .toRotationMatrix();
    const Eigen::Vector3d centre(rig.board.Width() / 2, rig.board.Height() / 2, 0);
    const double across = lateral(rng), down = lateral(rng);
    pose.translation() = Eigen::Vector3d(across * z, down * z, z) - pose.linear() * centre;
    frame.colour_from_board = pose;
    for (const auto& p : rig.board.InteriorCornerPoints()) {
      const Eigen::Vector2d px = Projected(rig.colour, pose * Eigen::Vector3d(p.x, p.y, p.z));
      const double du = pixel_noise(rng), dv = pixel_noise(rng);
      frame.colour_corners.emplace_back(px.x() + du, px.y() + dv);
    }
    DepthboardQuad quad;
    for (int c = 0; c < 4; ++c) {
      const double du = pixel_noise(rng), dv = pixel_noise(rng);
      quad.corners_px[static_cast<std::size_t>(c)] =
          Projected(rig.depth, rig.depth_from_colour * pose * outline[static_cast<std::size_t>(c)]) +
          Eigen::Vector2d(du, dv);
    }
    frame.quad = quad;
    for (int i = 1; i < 10; ++i)
      for (int j = 1; j < 8; ++j) {
        const Eigen::Vector3d in_depth =
            rig.depth_from_colour * pose * Eigen::Vector3d(rig.board.Width() * i / 10, rig.board.Height() * j / 8, 0);
        const Eigen::Vector2d px = Projected(rig.depth, in_depth);
        PairedSample s;
        s.frame = f, s.pose = f, s.u = px.x(), s.v = px.y();
        s.x = in_depth.x() / in_depth.z(), s.y = in_depth.y() / in_depth.z();
        s.raw = model::RawFromDepth(model::BaseForm::kReciprocal, rig.base.data(), in_depth.z()) + rig.tilt[0] * s.x +
                rig.tilt[1] * s.y + raw_noise(rng);
        out.samples.push_back(s);
        out.true_depths.push_back(in_depth.z());
      }
    out.frames.push_back(frame);
  }
  return out;
}

// Started where a user's separate steps leave it: the colour focal length
// 0.8 % off, the depth camera 2 % and 6 px off, the extrinsics 4 mm off
// along the axis. Each term started with a standard deviation is freed.
inline CameraCalibration Start(const Rig& rig) {
  CameraCalibration c;
  c.colour = Camera(rig.colour.camera_matrix(0, 0) * 1.008, rig.colour.camera_matrix(1, 1) * 1.008,
                    rig.colour.camera_matrix(0, 2) + 2, rig.colour.camera_matrix(1, 2) - 2, {0, 0, 0, 0, 0});
  c.depth = Camera(rig.depth.camera_matrix(0, 0) * 0.98, rig.depth.camera_matrix(1, 1) * 0.98,
                   rig.depth.camera_matrix(0, 2) + 6, rig.depth.camera_matrix(1, 2) - 4, {0, 0, 0, 0, 0});
  c.colour.stddev = c.depth.stddev = {1, 1, 1, 1, 0.01, 0.01, 0, 0, 0};
  c.colour.rms_reprojection_px = 0.1;
  c.depth_from_colour = rig.depth_from_colour;
  c.depth_from_colour.translation().z() += 0.004;
  c.extrinsics_rms_px = 0.1;
  return c;
}

inline Rig TestRig() {
  Rig rig;
  rig.colour = Camera(525, 524, 318, 243, {0.12, -0.25, 0, 0, 0});
  rig.depth = Camera(588.9, 587.5, 321.4, 252.1, {-0.08, 0.15, 0, 0, 0});
  rig.depth_from_colour.translation() = Eigen::Vector3d(-0.025, 0.001, 0.002);
  rig.depth_from_colour.linear() =
      Eigen::AngleAxisd(0.01, Eigen::Vector3d(0.3, 1, 0.1).normalized()).toRotationMatrix();
  return rig;
}

// A joint fit scored against its rig: each intrinsic's error in its stated
// sigmas (colour fx fy cx cy, then depth), and the samples' depths on their
// planes against the truth and their stated sigmas.
struct Score {
  std::vector<double> intrinsic_error_sigmas, intrinsic_sigma_px;
  double worst_depth_error = 0;  // relative
  double share_within_3_sigma = 0;
};

inline Score Scored(const JointCalibration& j, const Rig& rig, const Observations& seen) {
  Score s;
  const auto add = [&s](const CameraIntrinsics& got, const CameraIntrinsics& truth) {
    const std::array<std::pair<int, int>, 4> at = {{{0, 0}, {1, 1}, {0, 2}, {1, 2}}};
    for (std::size_t i = 0; i < 4; ++i) {
      const double sigma = got.stddev[i];
      const auto [r, c] = at[i];
      s.intrinsic_error_sigmas.push_back((got.camera_matrix(r, c) - truth.camera_matrix(r, c)) / sigma);
      s.intrinsic_sigma_px.push_back(sigma);
    }
  };
  add(j.cameras.colour, rig.colour);
  add(j.cameras.depth, rig.depth);
  int within = 0;
  for (std::size_t i = 0; i < seen.samples.size(); ++i) {
    const double error = j.depths[i] - seen.true_depths[i];
    double variance = j.residual_sigma_m[i] * j.residual_sigma_m[i];
    for (const auto& moved : j.perturbations) variance += std::pow(moved[i] - j.depths[i], 2);
    within += std::abs(error) <= 3 * std::sqrt(variance);
    s.worst_depth_error = std::max(s.worst_depth_error, std::abs(error) / seen.true_depths[i]);
  }
  s.share_within_3_sigma = within / static_cast<double>(seen.samples.size());
  return s;
}

}  // namespace speckle::joint::testing
