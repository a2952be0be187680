#pragma once
// The summary statistics of a set of residuals every fit and verdict reads.
#include <vector>

namespace speckle {

struct ResidualStats {
  int count = 0;
  double mean = 0, sigma = 0, rms = 0;
  double p05 = 0, p50 = 0, p95 = 0, max_abs = 0;
};
ResidualStats Summarize(std::vector<double> residuals);

}  // namespace speckle
