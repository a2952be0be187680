#include "stages/scaled_covariance.h"

#include <Eigen/Eigenvalues>

namespace speckle {

std::optional<BlockCovariance> ScaledCovariance(ceres::Problem& problem, double min_reciprocal_condition) {
  std::vector<double*> blocks;
  problem.GetParameterBlocks(&blocks);
  BlockCovariance out;
  std::vector<double*> free;
  int size = 0;
  for (double* block : blocks) {
    if (problem.IsParameterBlockConstant(block)) continue;
    free.push_back(block);
    out.offset[block] = size;
    size += problem.ParameterBlockTangentSize(block);
  }
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = free;
  ceres::CRSMatrix crs;
  if (!problem.Evaluate(options, nullptr, nullptr, nullptr, &crs) || crs.num_cols != size) return std::nullopt;
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(size, size);
  for (int r = 0; r < crs.num_rows; ++r)
    for (int i = crs.rows[r]; i < crs.rows[r + 1]; ++i)
      for (int j = crs.rows[r]; j < crs.rows[r + 1]; ++j)
        normal(crs.cols[i], crs.cols[j]) += crs.values[i] * crs.values[j];
  const Eigen::VectorXd scale = normal.diagonal().cwiseSqrt();
  if ((scale.array() <= 0).any() || !scale.allFinite()) return std::nullopt;
  const Eigen::MatrixXd scaled = scale.cwiseInverse().asDiagonal() * normal * scale.cwiseInverse().asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scaled);
  const Eigen::VectorXd values = eigen.eigenvalues();
  if (eigen.info() != Eigen::Success || !(values.minCoeff() > min_reciprocal_condition * values.maxCoeff()))
    return std::nullopt;
  const Eigen::MatrixXd inverse =
      eigen.eigenvectors() * values.cwiseInverse().asDiagonal() * eigen.eigenvectors().transpose();
  out.matrix = scale.cwiseInverse().asDiagonal() * inverse * scale.cwiseInverse().asDiagonal();
  return out;
}

std::vector<double> CameraCovariance(const Eigen::MatrixXd& matrix, const std::map<const double*, int>& offset,
                                     const double* k, const double* lens, double scale) {
  const auto start = [&](const double* block) {
    const auto at = offset.find(block);
    return at == offset.end() ? -1 : at->second;
  };
  const int k_at = start(k), lens_at = start(lens);
  int row[9];
  for (int i = 0; i < 9; ++i) row[i] = i < 4 ? (k_at < 0 ? -1 : k_at + i) : (lens_at < 0 ? -1 : lens_at + i - 4);
  std::vector<double> out(81, 0.0);
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j)
      if (row[i] >= 0 && row[j] >= 0)
        out[static_cast<std::size_t>(9 * i + j)] = 0.5 * scale * (matrix(row[i], row[j]) + matrix(row[j], row[i]));
  return out;
}

}  // namespace speckle
