#include "lab/fit/depth_uncertainty.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace speckle {

namespace {

// The depth sigma (mm) at covariates `c`: the parameters' covariance moved
// through the model's depth by its numeric gradient. `moved` is scratch, a
// copy of `m` (one copy for all rows: a formula effect is parsed on copy).
double SigmaMm(const NamedFit& f, const model::DepthModel& m, model::DepthModel& moved, const model::Covariates& c) {
  const double z = m.Depth(c);
  const std::size_t np = f.fit.parameters.size();
  std::vector<double> gradient(np);
  for (std::size_t i = 0; i < np; ++i) {
    std::vector<double> p = f.fit.parameters;
    const double h = 1e-6 * std::max(1e-6, std::abs(p[i]));
    p[i] += h;
    moved.SetFlat(p);
    gradient[i] = (moved.Depth(c) - z) / h;
  }
  double variance = 0;
  for (std::size_t i = 0; i < np; ++i)
    for (std::size_t j = 0; j < np; ++j) variance += gradient[i] * f.fit.covariance[i][j] * gradient[j];
  return 1000 * std::sqrt(std::max(0.0, variance));
}

// The raw value the model gives depth `z` at the image centre (twice, for
// effects that depend on the raw value itself); nullopt where the model
// gives none (a raw value is in the session's own units: 11-bit or mm).
std::optional<double> RawAt(const model::DepthModel& m, double z) {
  model::Covariates c;
  c.u = 320, c.v = 240;
  c.raw = m.PredictRaw(z, c);
  c.raw = m.PredictRaw(z, c);
  if (!std::isfinite(c.raw) || c.raw <= 0) return std::nullopt;
  return c.raw;
}

}  // namespace

std::vector<DepthSigma> DepthUncertainty(const NamedFit& f, const std::vector<PairedSample>& samples,
                                         const DepthUncertaintyOptions& options) {
  std::vector<DepthSigma> rows;
  if (samples.empty()) return rows;
  double low = 1e9, high = -1e9;
  for (const auto& s : samples) low = std::min(low, s.raw), high = std::max(high, s.raw);
  const model::DepthModel m = f.fit.Model();
  model::DepthModel moved = m;
  model::Covariates c;
  c.u = 320, c.v = 240;
  for (int k = 0; k <= 10; ++k) {
    c.raw = low + (high - low) * k / 10.0;
    rows.push_back({c.raw, m.Depth(c), SigmaMm(f, m, moved, c)});
  }
  const auto [nearest, farthest] = std::minmax_element(
      rows.begin(), rows.end(), [](const DepthSigma& a, const DepthSigma& b) { return a.depth_m < b.depth_m; });
  const double paired_near = nearest->depth_m, paired_far = farthest->depth_m;
  for (double z = options.near_m; z <= options.far_m + 1e-9; z += options.step_m) {
    if (z > paired_near - 0.5 * options.step_m && z < paired_far + 0.5 * options.step_m) continue;
    const std::optional<double> raw = RawAt(m, z);
    if (!raw) continue;
    c.raw = *raw;
    const double depth = m.Depth(c), sigma = SigmaMm(f, m, moved, c);
    if (std::isfinite(depth) && std::isfinite(sigma)) rows.push_back({c.raw, depth, sigma, true});
  }
  std::sort(rows.begin(), rows.end(), [](const DepthSigma& a, const DepthSigma& b) { return a.depth_m < b.depth_m; });
  return rows;
}

std::string DepthUncertaintyLine(const std::vector<DepthSigma>& rows, const CameraCalibration& cameras,
                                 double loose_share) {
  std::vector<DepthSigma> paired, beyond;
  for (const auto& r : rows) (r.extrapolated ? beyond : paired).push_back(r);
  if (paired.empty()) return {};
  const auto share = [](const DepthSigma& r) { return r.sigma_mm / (1000 * r.depth_m); };
  const auto by_depth = [](const DepthSigma& a, const DepthSigma& b) { return a.depth_m < b.depth_m; };
  const auto [near, far] = std::minmax_element(paired.begin(), paired.end(), by_depth);
  std::string out =
      fmt::format("depth sigma  ± {:.1f} mm ({:.2f} %) at {:.2f} m to ± {:.1f} mm ({:.2f} %) at {:.2f} m\n",
                  near->sigma_mm, 100 * share(*near), near->depth_m, far->sigma_mm, 100 * share(*far), far->depth_m);
  double worst = 0;
  for (const auto& r : paired) worst = std::max(worst, share(r));
  if (worst > loose_share) {
    // The two inputs that set a depth's scale and offset where no IR images
    // pin the depth camera: every board's distance follows the colour focal
    // length, and every depth the extrinsics' offset along the depth axis.
    const auto& c = cameras.colour;
    const double focal_share = 0.5 * (c.stddev[0] / c.camera_matrix(0, 0) + c.stddev[1] / c.camera_matrix(1, 1));
    const double tz = cameras.extrinsics_translation_sigma_m.z();
    // A colour camera given with sigmas (not fitted to any view) is as
    // loose as session.json states until the joint calibration refines it.
    const bool given = c.views == 0 && !cameras.joint;
    out += fmt::format(
        "             over {:.1f} %: the colour focal length is known to ± {:.2f} % {} and the "
        "extrinsics' depth offset {}; {}more board poses (tilted up to 30 degrees, near and far) or an IR "
        "chessboard recording narrow both\n",
        100 * loose_share, 100 * focal_share, given ? "as session.json states it" : "from the chessboard",
        tz > 0 ? fmt::format("to ± {:.1f} mm", 1000 * tz) : std::string("not at all (no fit bounded it)"),
        given && cameras.colour_prior ? "run-pipeline --joint-cameras refines it from the chessboards within those "
                                        "sigmas; "
                                      : "");
  }
  const auto farthest = std::max_element(beyond.begin(), beyond.end(), by_depth);
  if (farthest != beyond.end() && farthest->depth_m > far->depth_m) {
    // Past the farthest board the model extrapolates: its error there is not
    // measured, only implied by the parameters' covariance.
    out += fmt::format(
        "             beyond the boards' {:.2f} m the model extrapolates: ± {:.1f} mm ({:.2f} %) at {:.2f} m; "
        "boards out to there would measure it\n",
        far->depth_m, farthest->sigma_mm, 100 * share(*farthest), farthest->depth_m);
  }
  return out;
}

}  // namespace speckle
