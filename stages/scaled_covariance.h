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

namespace speckle {

struct BlockCovariance {
  Eigen::MatrixXd matrix;               // over every free block of the problem, in `offset`'s places
  std::map<const double*, int> offset;  // where each free block starts
  double Variance(const double* block, int i) const { return matrix(offset.at(block) + i, offset.at(block) + i); }
};

// nullopt when the scaled J^T J is singular: its smallest eigenvalue below
// `min_reciprocal_condition` times its largest.
std::optional<BlockCovariance> ScaledCovariance(ceres::Problem& problem, double min_reciprocal_condition = 1e-12);

}  // namespace speckle
