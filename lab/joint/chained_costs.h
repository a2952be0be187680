#pragma once
// The joint problem's two most numerous observations, a colour corner and a
// depth sample (joint_residuals.h), with their derivatives chained by hand
// through small jets instead of one jet over every parameter they read.
// Autodiff carried 25 derivatives (15 for a corner) through each rotation
// and each lens step, though each part reads only a few of them: the board
// plane reads the pose and the extrinsics, the ray the depth camera. The
// folds of the diagnosis spend most of their time here (bench/results/speed.md).
#include <ceres/ceres.h>

#include "lab/joint/joint_residuals.h"

namespace speckle::joint {

// Blocks: pose 6, depth k 4, depth lens 5 -> 2 residuals.
class ColourCornerCost : public ceres::SizedCostFunction<2, 6, 4, 5> {
 public:
  explicit ColourCornerCost(const ColourCorner& corner) : corner_(corner) {}

  bool Evaluate(double const* const* blocks, double* residual, double** jacobians) const override {
    if (!jacobians) return corner_(blocks[0], blocks[1], blocks[2], residual);
    // The board point in the colour camera, by the pose.
    using J6 = ceres::Jet<double, 6>;
    J6 pose[6], q6[3];
    for (int i = 0; i < 6; ++i) pose[i] = J6(blocks[0][i], i);
    Transform(pose, pose + 3, corner_.on_board.data(), q6);
    // Its pixel, by the point (0-2), the camera (3-6) and the lens (7-11).
    using J12 = ceres::Jet<double, 12>;
    J12 q[3], k[4], lens[5], pixel[2];
    for (int i = 0; i < 3; ++i) q[i] = J12(q6[i].a, i);
    for (int i = 0; i < 4; ++i) k[i] = J12(blocks[1][i], 3 + i);
    for (int i = 0; i < 5; ++i) lens[i] = J12(blocks[2][i], 7 + i);
    Project(k, lens, q, pixel);
    const double observed[2] = {corner_.observed.x(), corner_.observed.y()};
    for (int r = 0; r < 2; ++r) {
      residual[r] = (pixel[r].a - observed[r]) / corner_.sigma_px;
      const Eigen::Matrix<double, 12, 1> d = pixel[r].v / corner_.sigma_px;
      if (jacobians[0])
        for (int j = 0; j < 6; ++j) jacobians[0][r * 6 + j] = d[0] * q6[0].v[j] + d[1] * q6[1].v[j] + d[2] * q6[2].v[j];
      for (int j = 0; jacobians[1] && j < 4; ++j) jacobians[1][r * 4 + j] = d[3 + j];
      for (int j = 0; jacobians[2] && j < 5; ++j) jacobians[2][r * 5 + j] = d[7 + j];
    }
    return std::isfinite(residual[0]) && std::isfinite(residual[1]);
  }

 private:
  ColourCorner corner_;
};

// Blocks: pose 6, rotation 3, translation 3, depth k 4, depth lens 5, base
// base_size (2 or 3), billow 2 -> 1 residual.
class SampleRawCost : public ceres::CostFunction {
 public:
  SampleRawCost(const SampleRaw& sample, int base_size) : sample_(sample), base_size_(base_size) {
    set_num_residuals(1);
    *mutable_parameter_block_sizes() = {6, 3, 3, 4, 5, base_size, 2};
  }

  bool Evaluate(double const* const* blocks, double* residual, double** jacobians) const override {
    const double *pose = blocks[0], *rotation = blocks[1], *translation = blocks[2], *k = blocks[3], *lens = blocks[4],
                 *base = blocks[5], *billow = blocks[6];
    if (!jacobians) return sample_(pose, rotation, translation, k, lens, base, billow, residual);
    // The ray, by the depth camera (0-3) and its lens (4-8).
    using J9 = ceres::Jet<double, 9>;
    J9 k9[4], lens9[5], xy9[2];
    for (int i = 0; i < 4; ++i) k9[i] = J9(k[i], i);
    for (int i = 0; i < 5; ++i) lens9[i] = J9(lens[i], 4 + i);
    Undistort(k9, lens9, sample_.u, sample_.v, xy9);
    // The depth on the board plane, by the pose (0-5), the extrinsics (6-11) and the ray (12, 13).
    using J14 = ceres::Jet<double, 14>;
    J14 pose14[6], rotation14[3], translation14[3];
    for (int i = 0; i < 6; ++i) pose14[i] = J14(pose[i], i);
    for (int i = 0; i < 3; ++i) rotation14[i] = J14(rotation[i], 6 + i), translation14[i] = J14(translation[i], 9 + i);
    const J14 xy14[2] = {J14(xy9[0].a, 12), J14(xy9[1].a, 13)};
    const J14 z = DepthOnBoardPlane(pose14, rotation14, translation14, xy14);
    // The residual, by the depth (0), the ray (1, 2), the base form (3-5) and the billow (6, 7).
    using J8 = ceres::Jet<double, 8>;
    J8 xy8[2] = {J8(xy9[0].a, 1), J8(xy9[1].a, 2)}, base8[3], billow8[2] = {J8(billow[0], 6), J8(billow[1], 7)};
    for (int i = 0; i < base_size_; ++i) base8[i] = J8(base[i], 3 + i);
    const J8 r = sample_.RawResidual(J8(z.a, 0), xy8, base8, billow8);
    residual[0] = r.a;
    const double dx = r.v[1] + r.v[0] * z.v[12], dy = r.v[2] + r.v[0] * z.v[13];
    for (int j = 0; jacobians[0] && j < 6; ++j) jacobians[0][j] = r.v[0] * z.v[j];
    for (int j = 0; jacobians[1] && j < 3; ++j) jacobians[1][j] = r.v[0] * z.v[6 + j];
    for (int j = 0; jacobians[2] && j < 3; ++j) jacobians[2][j] = r.v[0] * z.v[9 + j];
    for (int j = 0; jacobians[3] && j < 4; ++j) jacobians[3][j] = dx * xy9[0].v[j] + dy * xy9[1].v[j];
    for (int j = 0; jacobians[4] && j < 5; ++j) jacobians[4][j] = dx * xy9[0].v[4 + j] + dy * xy9[1].v[4 + j];
    for (int j = 0; jacobians[5] && j < base_size_; ++j) jacobians[5][j] = r.v[3 + j];
    for (int j = 0; jacobians[6] && j < 2; ++j) jacobians[6][j] = r.v[6 + j];
    return std::isfinite(residual[0]);
  }

 private:
  SampleRaw sample_;
  int base_size_;
};

}  // namespace speckle::joint
