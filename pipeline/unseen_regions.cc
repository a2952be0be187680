#include "pipeline/unseen_regions.h"

#include <fmt/format.h>

#include <cmath>

#include "apply/depth_corrector.h"
#include "model/depth_model.h"

namespace speckle {
namespace {

// A third of the image across and down: corners, edges, the centre.
std::string RegionOf(int u, int v, int width, int height) {
  const int across = std::min(2, 3 * u / std::max(1, width)), down = std::min(2, 3 * v / std::max(1, height));
  static const char* kNames[3][3] = {{"the upper-left corner", "the top edge", "the upper-right corner"},
                                     {"the left edge", "the centre", "the right edge"},
                                     {"the lower-left corner", "the bottom edge", "the lower-right corner"}};
  return kNames[down][across];
}

// The sigma at `depth_m`, linear between the rows (the nearest row outside them).
double SigmaAt(const std::vector<DepthSigma>& rows, double depth_m) {
  if (rows.empty()) return 0;
  if (depth_m <= rows.front().depth_m) return rows.front().sigma_mm;
  for (std::size_t i = 1; i < rows.size(); ++i)
    if (depth_m <= rows[i].depth_m)
      return rows[i - 1].sigma_mm + (rows[i].sigma_mm - rows[i - 1].sigma_mm) * (depth_m - rows[i - 1].depth_m) /
                                        (rows[i].depth_m - rows[i - 1].depth_m);
  return rows.back().sigma_mm;
}

}  // namespace

std::optional<UnseenChange> LargestUnseenChange(const apply::DepthCalibration& parent,
                                                const apply::DepthCalibration& refit, const Coverage& coverage,
                                                const std::vector<DepthSigma>& sigma) {
  if (coverage.empty_cells == 0 || coverage.poses_per_cell.empty() || !(coverage.cell_px > 0)) return std::nullopt;
  const apply::DepthCorrector before(parent), after(refit);
  const int width = before.Width(), height = before.Height();
  if (after.Width() != width || after.Height() != height) return std::nullopt;
  const auto unseen = [&](int u, int v) {
    const int cu = static_cast<int>(u / coverage.cell_px), cv = static_cast<int>(v / coverage.cell_px);
    return cu < coverage.cells_u && cv < coverage.cells_v && coverage.poses_per_cell[cv * coverage.cells_u + cu] == 0;
  };
  UnseenChange out;
  out.unseen_share = static_cast<double>(coverage.empty_cells) / coverage.poses_per_cell.size();
  std::vector<std::uint16_t> raw(static_cast<std::size_t>(width) * height);
  std::vector<float> z0(raw.size()), z1(raw.size());
  const model::DepthModel& m = *parent.model;
  bool found = false;
  for (double depth_m : {0.5, 1.0, 2.0, 3.0}) {
    const double r = model::RawFromDepth(m.Definition().form, m.Base().data(), depth_m);
    if (!std::isfinite(r) || r < 1 || r > 65535) continue;
    std::fill(raw.begin(), raw.end(), static_cast<std::uint16_t>(std::lround(r)));
    before.Depth(raw, 0, z0);
    after.Depth(raw, 0, z1);
    // Against the change where poses reached: a refit that moves every depth
    // alike (its base form's scale) extrapolates nothing.
    std::vector<double> seen;
    for (int v = 0; v < height; v += 4)
      for (int u = 0; u < width; u += 4) {
        const std::size_t p = static_cast<std::size_t>(v) * width + u;
        if (!unseen(u, v) && std::isfinite(z1[p] - z0[p])) seen.push_back(static_cast<double>(z1[p]) - z0[p]);
      }
    if (seen.empty()) continue;
    std::nth_element(seen.begin(), seen.begin() + seen.size() / 2, seen.end());
    const double typical = seen[seen.size() / 2];
    for (int v = 0; v < height; ++v)
      for (int u = 0; u < width; ++u) {
        const std::size_t p = static_cast<std::size_t>(v) * width + u;
        const double moved = 1000 * std::abs(static_cast<double>(z1[p]) - z0[p] - typical);
        if (!std::isfinite(moved) || !unseen(u, v) || (found && moved <= out.moved_mm)) continue;
        out.moved_mm = moved, out.u = u, out.v = v, out.depth_m = depth_m, found = true;
      }
  }
  if (!found) return std::nullopt;
  out.sigma_mm = SigmaAt(sigma, out.depth_m);
  out.region = RegionOf(out.u, out.v, width, height);
  return out;
}

nlohmann::json ToJson(const UnseenChange& c) {
  return {{"unseen_share", c.unseen_share},
          {"depth_m", c.depth_m},
          {"moved_mm", c.moved_mm},
          {"u", c.u},
          {"v", c.v},
          {"sigma_mm", c.sigma_mm},
          {"region", c.region},
          {"beyond_sigma", c.BeyondSigma()}};
}

std::string UnseenChangeWarning(const UnseenChange& c, const std::string& parent_name) {
  if (!c.BeyondSigma()) return "";
  return fmt::format(
      "where no board pose reached ({:.0f} % of the image), this refit moves the depth by up to {:.0f} mm against {} "
      "(a flat scene at {:.2f} m, pixel ({}, {}) in {}), beyond its ± {:.1f} mm at the image centre: the model is "
      "extrapolated there; record board poses over {} before using depths there",
      100 * c.unseen_share, c.moved_mm, parent_name, c.depth_m, c.u, c.v, c.region, c.sigma_mm, c.region);
}

std::string UnseenChangeLine(const UnseenChange& c, const std::string& parent_name) {
  if (c.BeyondSigma()) return "warning      " + UnseenChangeWarning(c, parent_name) + "\n";
  return fmt::format(
      "             where no board pose reached ({:.0f} % of the image), the depth moves by at most {:.1f} mm "
      "against {}: within its sigma\n",
      100 * c.unseen_share, c.moved_mm, parent_name);
}

}  // namespace speckle
