#include "model/undistortion_grid.h"

#include <algorithm>
#include <cmath>

namespace speckle {

const char* ToString(TrueRawMethod method) {
  switch (method) {
    case TrueRawMethod::kImageMinimum: return "image_minimum";
    case TrueRawMethod::kHyperboloid: return "hyperboloid";
    case TrueRawMethod::kCentreMinimum: return "centre_minimum";
    case TrueRawMethod::kOwnPlane: return "own_plane";
  }
  return "?";
}

double UndistortionGrid::Apply(double raw, double x, double y) const {
  if (nx == 0 || raw_nodes.size() < 2) return raw;
  // Continuous cell coordinates (cell centres at integers).
  const double fi = std::clamp((x - x_min) / (x_max - x_min) * nx - 0.5, 0.0, nx - 1.0);
  const double fj = std::clamp((y - y_min) / (y_max - y_min) * ny - 0.5, 0.0, ny - 1.0);
  const auto upper = std::upper_bound(raw_nodes.begin(), raw_nodes.end(), raw);
  const int k1 = std::clamp(static_cast<int>(upper - raw_nodes.begin()), 1, static_cast<int>(raw_nodes.size()) - 1);
  const double fk = std::clamp((raw - raw_nodes[k1 - 1]) / (raw_nodes[k1] - raw_nodes[k1 - 1]), 0.0, 1.0);
  const int i0 = static_cast<int>(fi), j0 = static_cast<int>(fj);
  const int i1 = std::min(i0 + 1, nx - 1), j1 = std::min(j0 + 1, ny - 1);
  const double ti = fi - i0, tj = fj - j0;
  double value = 0;
  for (int dk = 0; dk < 2; ++dk) {
    const int k = k1 - 1 + dk;
    const double wk = dk ? fk : 1 - fk;
    value += wk * ((1 - tj) * ((1 - ti) * correction[Index(k, j0, i0)] + ti * correction[Index(k, j0, i1)]) +
                   tj * ((1 - ti) * correction[Index(k, j1, i0)] + ti * correction[Index(k, j1, i1)]));
  }
  return raw + value;
}

double UndistortionGrid::SupportedShare() const {
  if (supported.empty()) return 0;
  return static_cast<double>(std::count(supported.begin(), supported.end(), 1)) / supported.size();
}

}  // namespace speckle
