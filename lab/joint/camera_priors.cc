#include "lab/joint/camera_priors.h"

#include <ceres/manifold.h>
#include <ceres/normal_prior.h>

#include <algorithm>

namespace speckle::joint {
namespace {

// One block's prior, `sigma` per term (0: held at its given value). A block
// whose terms a manifold holds already (HoldUnsupported: the terms the start
// held) keeps it, and those terms were named there.
void AddBlockPrior(const double* given, const double* sigma, int size, double* block, ceres::Problem& problem,
                   Kinds& kinds, const std::vector<std::string>& names, const std::string& camera,
                   std::vector<std::string>* held, const std::vector<int>& unweighed = {}) {
  if (!problem.HasParameterBlock(block) || problem.IsParameterBlockConstant(block)) return;
  std::vector<int> exact, weighed;
  for (int i = 0; i < size; ++i)
    if (std::find(unweighed.begin(), unweighed.end(), i) == unweighed.end())
      (sigma[i] > 0 ? weighed : exact).push_back(i);
  const bool named = problem.HasManifold(block);
  for (int i : exact) {
    block[i] = given[i];
    if (!named) held->push_back(camera + " " + names[static_cast<std::size_t>(i)] + " (given exactly)");
  }
  if (weighed.empty()) {
    if (static_cast<int>(exact.size()) == size) {
      problem.SetParameterBlockConstant(block);
    } else if (!exact.empty() && !named) {
      problem.SetManifold(block, new ceres::SubsetManifold(size, exact));
    }
    return;
  }
  if (!exact.empty() && !named) problem.SetManifold(block, new ceres::SubsetManifold(size, exact));
  ceres::Matrix a = ceres::Matrix::Zero(static_cast<int>(weighed.size()), size);
  ceres::Vector b(size);
  for (int i = 0; i < size; ++i) b(i) = given[i];
  for (std::size_t row = 0; row < weighed.size(); ++row)
    a(static_cast<int>(row), weighed[row]) = 1.0 / sigma[weighed[row]];
  kinds.Add(kinds.prior, problem.AddResidualBlock(new ceres::NormalPrior(a, b), nullptr, block), -1);
}

// `free_principal_point`: the prior's cx, cy are not the fitted camera's
// (a depth camera's prior is the IR image's; see HoldWhatIsNotFitted).
void AddCameraPrior(const std::optional<CameraIntrinsics>& prior, double* k, double* lens, const std::string& camera,
                    bool free_principal_point, ceres::Problem& problem, Kinds& kinds, std::vector<std::string>* held) {
  if (!prior) return;
  double given_k[4], given_lens[5];
  ToBlocks(*prior, given_k, given_lens);
  AddBlockPrior(given_k, prior->stddev.data(), 4, k, problem, kinds, {"fx", "fy", "cx", "cy"}, camera, held,
                free_principal_point ? std::vector<int>{2, 3} : std::vector<int>{});
  AddBlockPrior(given_lens, prior->stddev.data() + 4, 5, lens, problem, kinds, {"k1", "k2", "p1", "p2", "k3"}, camera,
                held);
}

}  // namespace

void AddCameraPriors(const JointInput& in, Blocks& b, ceres::Problem& problem, Kinds& kinds,
                     std::vector<std::string>* held) {
  AddCameraPrior(in.cameras.colour_prior, b.colour_k, b.colour_lens, "colour", false, problem, kinds, held);
  AddCameraPrior(in.cameras.depth_prior, b.depth_k, b.depth_lens, "depth", true, problem, kinds, held);
}

}  // namespace speckle::joint
