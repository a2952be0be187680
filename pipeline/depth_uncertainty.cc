#include "pipeline/depth_uncertainty.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace speckle {

std::vector<DepthSigma> DepthUncertainty(const NamedFit& f, const std::vector<PairedSample>& samples) {
  std::vector<DepthSigma> rows;
  if (samples.empty()) return rows;
  double low = 1e9, high = -1e9;
  for (const auto& s : samples) low = std::min(low, s.raw), high = std::max(high, s.raw);
  const model::DepthModel m = f.fit.Model();
  const std::size_t np = f.fit.parameters.size();
  for (int k = 0; k <= 10; ++k) {
    model::Covariates c;
    c.raw = low + (high - low) * k / 10.0;
    c.u = 320, c.v = 240;
    const double z = m.Depth(c);
    std::vector<double> gradient(np);
    for (std::size_t i = 0; i < np; ++i) {
      model::DepthModel moved = m;
      std::vector<double> p = f.fit.parameters;
      const double h = 1e-6 * std::max(1e-6, std::abs(p[i]));
      p[i] += h;
      moved.SetFlat(p);
      gradient[i] = (moved.Depth(c) - z) / h;
    }
    double variance = 0;
    for (std::size_t i = 0; i < np; ++i)
      for (std::size_t j = 0; j < np; ++j) variance += gradient[i] * f.fit.covariance[i][j] * gradient[j];
    rows.push_back({c.raw, z, 1000 * std::sqrt(std::max(0.0, variance))});
  }
  return rows;
}

std::string DepthUncertaintyLine(const std::vector<DepthSigma>& rows, const CameraCalibration& cameras,
                                 double loose_share) {
  if (rows.empty()) return {};
  const auto share = [](const DepthSigma& r) { return r.sigma_mm / (1000 * r.depth_m); };
  const DepthSigma &near = rows.front().depth_m < rows.back().depth_m ? rows.front() : rows.back(),
                   &far = &near == &rows.front() ? rows.back() : rows.front();
  std::string out =
      fmt::format("depth sigma  ± {:.1f} mm ({:.2f} %) at {:.2f} m to ± {:.1f} mm ({:.2f} %) at {:.2f} m\n",
                  near.sigma_mm, 100 * share(near), near.depth_m, far.sigma_mm, 100 * share(far), far.depth_m);
  double worst = 0;
  for (const auto& r : rows) worst = std::max(worst, share(r));
  if (worst <= loose_share) return out;
  // The two inputs that set a depth's scale and offset where no IR images
  // pin the depth camera: every board's distance follows the colour focal
  // length, and every depth the extrinsics' offset along the depth axis.
  const auto& c = cameras.colour;
  const double focal_share = 0.5 * (c.stddev[0] / c.camera_matrix(0, 0) + c.stddev[1] / c.camera_matrix(1, 1));
  out += fmt::format(
      "             over {:.1f} %: the colour focal length is known to ± {:.2f} % from the chessboard and the "
      "extrinsics' "
      "depth offset to ± {:.1f} mm; more board poses (tilted up to 30 degrees, near and far) or an IR chessboard "
      "recording narrow both\n",
      100 * loose_share, 100 * focal_share, 1000 * cameras.extrinsics_translation_sigma_m.z());
  return out;
}

}  // namespace speckle
