#include "lab/joint/cluster_covariance.h"

#include <ceres/cost_function.h>
#include <ceres/manifold.h>

#include <Eigen/Eigenvalues>
#include <map>

namespace speckle::joint {
namespace {

// Where each free block's tangent coordinates start, and how each maps to
// its ambient coordinates (the manifold's plus-Jacobian at the minimum).
struct TangentLayout {
  std::map<const double*, int> tangent_at, ambient_at;
  std::map<const double*, Eigen::MatrixXd> plus_jacobian;  // ambient x tangent
  int tangent = 0, ambient = 0;
};

TangentLayout LayoutOf(ceres::Problem& problem, const std::vector<const double*>& blocks) {
  TangentLayout l;
  for (const double* b : blocks) {
    const int ambient = problem.ParameterBlockSize(b);
    l.ambient_at[b] = l.ambient;
    l.ambient += ambient;
    if (problem.IsParameterBlockConstant(b)) continue;
    const int tangent = problem.ParameterBlockTangentSize(b);
    Eigen::MatrixXd plus = Eigen::MatrixXd::Identity(ambient, tangent);
    if (const ceres::Manifold* m = problem.GetManifold(b)) {
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> j(ambient, tangent);
      m->PlusJacobian(b, j.data());
      plus = j;
    }
    l.plus_jacobian[b] = plus;
    l.tangent_at[b] = l.tangent;
    l.tangent += tangent;
  }
  return l;
}

// The smallest covariance at least as large as both in every direction:
// with V^T A V = I and V^T B V = L (the generalized eigenvectors of B
// against A), A = W W^T and B = W L W^T for W = A V, and the larger is
// W max(1, L) W^T. The robust estimate's own scatter is large with few
// clusters: over 16 draws of 20 poses with independent errors, the colour
// principal point's robust sigma ranged 0.11-0.40 px against 0.17-0.35 px
// counted as independent, and its errors in robust sigmas scattered 1.7
// times as wide as they should (1.2 counted as independent).
Eigen::MatrixXd LargerInEveryDirection(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> s(b, a);
  const Eigen::MatrixXd w = a * s.eigenvectors();
  return w * s.eigenvalues().cwiseMax(1.0).asDiagonal() * w.transpose();
}

}  // namespace

std::optional<Eigen::MatrixXd> ClusterRobustCovariance(ceres::Problem& problem,
                                                       const std::vector<ceres::ResidualBlockId>& residuals,
                                                       const std::vector<int>& cluster,
                                                       const std::vector<const double*>& blocks) {
  const TangentLayout l = LayoutOf(problem, blocks);
  Eigen::MatrixXd hessian = Eigen::MatrixXd::Zero(l.tangent, l.tangent);
  Eigen::MatrixXd independent_information = Eigen::MatrixXd::Zero(l.tangent, l.tangent);  // cluster < 0
  std::map<int, Eigen::VectorXd> gradient;                                                // by cluster
  std::vector<double*> parameters;
  for (std::size_t r = 0; r < residuals.size(); ++r) {
    problem.GetParameterBlocksForResidualBlock(residuals[r], &parameters);
    const int rows = problem.GetCostFunctionForResidualBlock(residuals[r])->num_residuals();
    std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> jacobian(parameters.size());
    std::vector<double*> pointers(parameters.size(), nullptr);
    for (std::size_t k = 0; k < parameters.size(); ++k) {
      if (!l.tangent_at.count(parameters[k])) continue;  // held, or not asked for
      jacobian[k].resize(rows, problem.ParameterBlockTangentSize(parameters[k]));
      pointers[k] = jacobian[k].data();
    }
    Eigen::VectorXd residual(rows);
    double cost = 0;
    if (!problem.EvaluateResidualBlock(residuals[r], true, &cost, residual.data(), pointers.data()))
      return std::nullopt;
    // Only the blocks this residual reaches: a dense row of every pose cost
    // a second at 10,000 residuals.
    Eigen::VectorXd* clustered = nullptr;
    if (cluster[r] >= 0) clustered = &gradient.try_emplace(cluster[r], Eigen::VectorXd::Zero(l.tangent)).first->second;
    Eigen::MatrixXd& information = clustered ? hessian : independent_information;
    for (std::size_t k = 0; k < parameters.size(); ++k) {
      if (!pointers[k]) continue;
      const int tk = l.tangent_at.at(parameters[k]);
      if (clustered) clustered->segment(tk, jacobian[k].cols()).noalias() += jacobian[k].transpose() * residual;
      for (std::size_t m = 0; m < parameters.size(); ++m)
        if (pointers[m])
          information.block(tk, l.tangent_at.at(parameters[m]), jacobian[k].cols(), jacobian[m].cols()).noalias() +=
              jacobian[k].transpose() * jacobian[m];
    }
  }
  if (gradient.size() < 2) return std::nullopt;
  hessian += independent_information;
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(l.tangent, l.tangent);
  for (const auto& [c, g] : gradient) meat.noalias() += g * g.transpose();
  // Inverted with Jacobi scaling: the parameters' units span twenty orders
  // of magnitude in the Hessian (a base form's slope against a billow in raw^2).
  const Eigen::VectorXd diagonal = hessian.diagonal();
  if (!(diagonal.minCoeff() > 0)) return std::nullopt;  // a free parameter no residual moves
  const Eigen::VectorXd scale = diagonal.cwiseSqrt().cwiseInverse();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scale.asDiagonal() * hessian * scale.asDiagonal());
  const Eigen::VectorXd values = eigen.eigenvalues();
  if (!(values.minCoeff() > 1e-12 * values.maxCoeff())) return std::nullopt;
  const Eigen::MatrixXd independent =
      eigen.eigenvectors() * values.cwiseInverse().asDiagonal() * eigen.eigenvectors().transpose();
  const double groups = static_cast<double>(gradient.size());
  meat *= groups / (groups - 1);
  meat += independent_information;
  const Eigen::MatrixXd robust = independent * scale.asDiagonal() * meat * scale.asDiagonal() * independent;
  const Eigen::MatrixXd tangent = scale.asDiagonal() * LargerInEveryDirection(independent, robust) * scale.asDiagonal();
  // Into the ambient coordinates: C = P T P^T, P the plus-Jacobians.
  Eigen::MatrixXd lift = Eigen::MatrixXd::Zero(l.ambient, l.tangent);
  for (const auto& [b, plus] : l.plus_jacobian)
    lift.block(l.ambient_at.at(b), l.tangent_at.at(b), plus.rows(), plus.cols()) = plus;
  return Eigen::MatrixXd(lift * tangent * lift.transpose());
}

}  // namespace speckle::joint
