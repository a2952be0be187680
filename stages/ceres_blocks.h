#pragma once
// The one way Speckle's Ceres problems hold parameter blocks constant, bound
// them or ask whether they are free. Ceres CHECK-fails (SIGABRT) when a block
// is not in the problem, e.g. a block no residual uses because every view was
// rejected, and when a block has size 0 (a formula with no parameters): here a
// block the problem does not hold is simply not estimated, and a size-0 block
// is refused with a message before Ceres sees it.
#include <ceres/problem.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace speckle {

// Holds `block` at its value; a block the problem does not hold is already
// not estimated, so there is nothing to do.
inline void HoldConstant(ceres::Problem& problem, double* block) {
  if (problem.HasParameterBlock(block)) problem.SetParameterBlockConstant(block);
}

// Bounds parameter `index` of `block` to [lower, upper]; an infinite or
// beyond-1e29 bound (our "none") is not set.
inline void BoundParameter(ceres::Problem& problem, double* block, int index, double lower, double upper) {
  if (!problem.HasParameterBlock(block)) return;
  if (index < 0 || index >= problem.ParameterBlockSize(block))
    throw std::logic_error("BoundParameter: index " + std::to_string(index) + " outside its block");
  if (std::isfinite(lower) && lower > -1e29) problem.SetParameterLowerBound(block, index, lower);
  if (std::isfinite(upper) && upper < 1e29) problem.SetParameterUpperBound(block, index, upper);
}

// True when the problem estimates `block`.
inline bool IsFree(const ceres::Problem& problem, const double* block) {
  return problem.HasParameterBlock(block) && !problem.IsParameterBlockConstant(block);
}

// Refuses a cost function with a block of size 0 (Ceres would abort).
inline void RequireNonEmptyBlocks(const std::vector<int>& block_sizes, const std::string& what) {
  for (std::size_t i = 0; i < block_sizes.size(); ++i)
    if (block_sizes[i] <= 0)
      throw std::invalid_argument(what + ": parameter block " + std::to_string(i) + " has no parameters");
}

}  // namespace speckle
