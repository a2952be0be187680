#include "lab/stats/residual_stats.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace speckle {

ResidualStats Summarize(std::vector<double> r) {
  r.erase(std::remove_if(r.begin(), r.end(), [](double v) { return !std::isfinite(v); }), r.end());
  ResidualStats s;
  s.count = static_cast<int>(r.size());
  if (r.empty()) return s;
  const double n = static_cast<double>(r.size());
  s.mean = std::accumulate(r.begin(), r.end(), 0.0) / n;
  double sq = 0, dev = 0;
  for (double v : r) {
    sq += v * v;
    dev += (v - s.mean) * (v - s.mean);
    s.max_abs = std::max(s.max_abs, std::abs(v));
  }
  s.rms = std::sqrt(sq / n);
  s.sigma = r.size() > 1 ? std::sqrt(dev / (n - 1)) : 0;
  std::sort(r.begin(), r.end());
  const auto at = [&](double q) { return r[static_cast<std::size_t>(q * (n - 1))]; };
  s.p05 = at(0.05);
  s.p50 = at(0.5);
  s.p95 = at(0.95);
  return s;
}

}  // namespace speckle
