#include "lab/diagnosis/coverage.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace speckle {

Coverage AssessCoverage(const DiagnosisOptions& options, const std::vector<PairedSample>& samples, const DepthFit& fit,
                        double floor_raw, double held_out_rms) {
  Coverage c;
  c.cell_px = options.coverage_cell_px;
  c.min_poses = options.min_poses_per_cell;
  c.parameters = static_cast<int>(fit.parameters.size());
  c.in_sample_rms = fit.raw.rms;
  const model::DepthModel model = fit.Model();  // Effects() is the model's: keep it alive over the loop
  for (const auto& effect : model.Effects())
    for (const std::string& read : effect->CovariatesRead()) c.model_reads.insert(read);
  const auto cell_of = [&](double px) { return std::max(0, static_cast<int>(px / c.cell_px)); };
  const auto placed = [](const PairedSample& s) { return std::isfinite(s.u) && std::isfinite(s.v); };
  c.cells_u = cell_of(options.image_width_px - 1) + 1, c.cells_v = cell_of(options.image_height_px - 1) + 1;
  for (const auto& s : samples)
    if (placed(s)) c.cells_u = std::max(c.cells_u, cell_of(s.u) + 1), c.cells_v = std::max(c.cells_v, cell_of(s.v) + 1);
  std::vector<std::set<int>> reached(static_cast<std::size_t>(c.cells_u * c.cells_v));
  std::set<int> poses;
  for (const auto& s : samples) {
    if (!placed(s)) continue;
    reached[static_cast<std::size_t>(cell_of(s.v) * c.cells_u + cell_of(s.u))].insert(s.pose);
    poses.insert(s.pose);
  }
  c.poses = static_cast<int>(poses.size());
  for (int k = 0; k < c.cells_u * c.cells_v; ++k) {
    const std::set<int>& cell = reached[static_cast<std::size_t>(k)];
    c.poses_per_cell.push_back(static_cast<int>(cell.size()));
    if (cell.empty()) {
      ++c.empty_cells;
    } else if (static_cast<int>(cell.size()) < c.min_poses) {
      const int u0 = static_cast<int>((k % c.cells_u) * c.cell_px), v0 = static_cast<int>((k / c.cells_u) * c.cell_px);
      c.sparse.push_back(
          {u0, v0, u0 + static_cast<int>(c.cell_px), v0 + static_cast<int>(c.cell_px), {cell.begin(), cell.end()}});
    }
  }
  // The cells fewest poses reach first: where one more pose helps most.
  std::stable_sort(c.sparse.begin(), c.sparse.end(),
                   [](const auto& a, const auto& b) { return a.poses.size() < b.poses.size(); });
  // Held out, each pose is predicted by parameters the other poses measured;
  // in-sample, by parameters it helped measure. A model that reaches the
  // floor only in-sample has parameters the poses do not pin down.
  const double excess = held_out_rms * held_out_rms - floor_raw * floor_raw;
  const double gap = held_out_rms * held_out_rms - c.in_sample_rms * c.in_sample_rms;
  c.under_determined = floor_raw > 0 && held_out_rms > options.complete_ratio * floor_raw &&
                       c.in_sample_rms <= options.complete_ratio * floor_raw &&
                       gap >= options.under_determined_share * excess;
  return c;
}

// The covariates (model/covariates.h names) that take one value over every
// sample: an effect reading only those is one offset, the base form's.

}  // namespace speckle
