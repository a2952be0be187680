#pragma once
// The covariance of a fitted problem's free parameters, (J^T J)^-1, with the
// Jacobian's columns scaled to unit norm before the inverse and unscaled
// after (the same matrix in exact arithmetic). Ceres' Covariance judges the
// rank on the unscaled Jacobian: in the outline calibration the board
// planes' billow (raw^2) has columns nine orders below the base form's, and
// Ceres' SPARSE_QR took them for zero and the problem for rank-deficient
// (a clean simulated session stopped with "its covariance is singular",
// though the scaled Jacobian's condition number was 240).
#include <ceres/ceres.h>

#include <Eigen/Core>
#include <map>
#include <optional>
#include <vector>

namespace speckle {

struct BlockCovariance {
  Eigen::MatrixXd matrix;               // over every free block of the problem, in `offset`'s places
  std::map<const double*, int> offset;  // where each free block starts
  double Variance(const double* block, int i) const { return matrix(offset.at(block) + i, offset.at(block) + i); }
};

// A camera's fx, fy, cx, cy, k1, k2, p1, p2, k3 covariance (81 values,
// row-major, exactly symmetric) from a fit's `matrix` times `scale`, whose
// free blocks start at `offset`: the camera's intrinsics block `k` and lens
// block `lens` (one not in `offset` was held: its rows are zero).
std::vector<double> CameraCovariance(const Eigen::MatrixXd& matrix, const std::map<const double*, int>& offset,
                                     const double* k, const double* lens, double scale = 1);

// nullopt when the scaled J^T J is singular: its smallest eigenvalue below
// `min_reciprocal_condition` times its largest.
std::optional<BlockCovariance> ScaledCovariance(ceres::Problem& problem, double min_reciprocal_condition = 1e-12);

}  // namespace speckle
