#pragma once
// The three kinds of observation in the joint calibration (joint_calibration.h),
// each a residual in units of its own noise, autodiffed through every camera
// it passes:
//   - a colour chessboard corner: the board point through its pose and the
//     colour camera;
//   - a depth outline corner: the board's outer corner through its pose, the
//     extrinsics and the depth camera, moved outwards by the edge offset;
//   - a depth sample: its raw value against the raw value the base form gives
//     for the depth where its pixel's ray (through the depth camera's lens)
//     meets the board's plane (Herrera et al.'s joint formulation).
// Parameter blocks: a board pose is one block (angle-axis rotation, then
// translation: Schur elimination takes a pose as one block); the extrinsics
// are a rotation (3) and a translation (3); a camera is (fx, fy, cx, cy) and
// its Brown-Conrady lens (k1, k2, p1, p2, k3).
#include <ceres/rotation.h>

#include <Eigen/Core>

#include "model/base_form.h"
#include "stages/lens_autodiff.h"

namespace speckle::joint {

// `point` moved by rotation and translation.
template <typename T, typename P>
void Transform(const T* rotation, const T* translation, const P* point, T* out) {
  const T p[3] = {T(point[0]), T(point[1]), T(point[2])};
  ceres::AngleAxisRotatePoint(rotation, p, out);
  for (int i = 0; i < 3; ++i) out[i] += translation[i];
}

struct ColourCorner {
  ColourCorner(const Eigen::Vector3d& on_board, const Eigen::Vector2d& observed, double sigma_px)
      : on_board(on_board), observed(observed), sigma_px(sigma_px) {}
  template <typename T>
  bool operator()(const T* pose, const T* k, const T* lens, T* residual) const {
    T q[3], pixel[2];
    Transform(pose, pose + 3, on_board.data(), q);
    Project(k, lens, q, pixel);
    residual[0] = (pixel[0] - T(observed.x())) / T(sigma_px);
    residual[1] = (pixel[1] - T(observed.y())) / T(sigma_px);
    return true;
  }
  Eigen::Vector3d on_board;
  Eigen::Vector2d observed;
  double sigma_px;
};

// The outline corner where the depth exposure saw it: the board moved on
// by `velocity` (colour-camera m/s) for the delay between the exposures.
struct OutlineCorner {
  OutlineCorner(const Eigen::Vector3d& on_board, const Eigen::Vector3d& velocity, const Eigen::Vector2d& observed,
                const Eigen::Vector2d& outward, double sigma_px)
      : on_board(on_board), velocity(velocity), observed(observed), outward(outward), sigma_px(sigma_px) {}
  template <typename T>
  bool operator()(const T* pose, const T* rotation, const T* translation, const T* k, const T* lens,
                  const T* edge_offset, const T* delay_s, T* residual) const {
    T in_colour[3], in_depth[3], pixel[2];
    Transform(pose, pose + 3, on_board.data(), in_colour);
    for (int i = 0; i < 3; ++i) in_colour[i] += delay_s[0] * T(velocity[i]);
    Transform(rotation, translation, in_colour, in_depth);
    Project(k, lens, in_depth, pixel);
    residual[0] = (pixel[0] + edge_offset[0] * T(outward.x()) - T(observed.x())) / T(sigma_px);
    residual[1] = (pixel[1] + edge_offset[0] * T(outward.y()) - T(observed.y())) / T(sigma_px);
    return true;
  }
  Eigen::Vector3d on_board, velocity;
  Eigen::Vector2d observed, outward;
  double sigma_px;
};

// The depth where a depth pixel's ray (its normalized coordinates xy) meets the board's plane: the plane's
// normal and offset moved from the board, through the colour camera, into
// the depth camera.
template <typename T>
T DepthOnBoardPlane(const T* pose, const T* rotation, const T* translation, const T* xy) {
  const T board_normal[3] = {T(0), T(0), T(1)};
  T normal_c[3], normal[3], origin[3];
  ceres::AngleAxisRotatePoint(pose, board_normal, normal_c);
  ceres::AngleAxisRotatePoint(rotation, normal_c, normal);
  Transform(rotation, translation, pose + 3, origin);  // the board's origin in the depth camera
  const T offset = normal[0] * origin[0] + normal[1] * origin[1] + normal[2] * origin[2];
  return offset / (normal[0] * xy[0] + normal[1] * xy[1] + normal[2]);
}

// The raw value is billowed as a wide-angle adapter billows it (see
// stages/outline_calibration.cc's PlaneRaw): bx and by are nuisance
// parameters here, bounded below by zero, so the lens does not take it up.
struct SampleRaw {
  SampleRaw(double u, double v, double raw, double sigma, model::BaseForm form)
      : u(u), v(v), raw(raw), sigma(sigma), form(form) {}
  template <typename T>
  bool operator()(const T* pose, const T* rotation, const T* translation, const T* k, const T* lens, const T* base,
                  const T* billow, T* residual) const {
    T xy[2];
    Undistort(k, lens, u, v, xy);
    residual[0] = RawResidual(DepthOnBoardPlane(pose, rotation, translation, xy), xy, base, billow);
    return true;
  }
  // The residual at depth z on the ray xy (chained_costs.h differentiates the parts apart).
  template <typename T>
  T RawResidual(const T& z, const T* xy, const T* base, const T* billow) const {
    const T predicted = model::RawFromDepth(form, base, z);
    const T b = billow[0] * xy[0] * xy[0] + billow[1] * xy[1] * xy[1];
    // sqrt(raw^2 + b) written as raw plus its excess, which keeps the sign of
    // a raw value the fit's early steps may drive below zero.
    return (T(raw) - predicted - b / (sqrt(predicted * predicted + b) + abs(predicted))) / T(sigma);
  }
  double u, v, raw, sigma;
  model::BaseForm form;
};

// A sample's depth alone, for its derivatives through every block it passes.
struct SampleDepth {
  SampleDepth(double u, double v) : u(u), v(v) {}
  template <typename T>
  bool operator()(const T* pose, const T* rotation, const T* translation, const T* k, const T* lens, T* z) const {
    T xy[2];
    Undistort(k, lens, u, v, xy);
    z[0] = DepthOnBoardPlane(pose, rotation, translation, xy);
    return true;
  }
  double u, v;
};

}  // namespace speckle::joint
