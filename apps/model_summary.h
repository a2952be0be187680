#pragma once
// The terminal summary of a fitted model and its diagnosis, shared by
// run-pipeline and refit.
#include <fmt/format.h>

#include <map>

#include "lab/model_lab.h"

namespace speckle {

// What the user must know of parameters the samples do not determine.
inline std::string UnidentifiedLine(const DepthFit& fit) {
  if (fit.unidentified.empty()) return "";
  std::string names;
  for (const std::size_t i : fit.unidentified) {
    const auto& n = fit.names[i];
    names += (names.empty() ? "" : ", ") + (n.block == "base" ? "" : n.block + ".") + n.name;
  }
  return fmt::format(
      "             not identified: {}: no sample's raw value depends on them, or they change it as other "
      "parameters do, so their values are arbitrary and their sigma null in calibration.json; drop them from the "
      "model, or record what tells them apart\n",
      names);
}

inline std::string ModelSummary(const ModelLab& lab) {
  const NamedFit& m = lab.Chosen();
  std::string out = fmt::format("model        {}\n", m.name);
  // Spatial fields have dozens of control values: those blocks get one line.
  std::map<std::string, int> block_size;
  for (const auto& n : m.fit.names) ++block_size[n.block];
  for (std::size_t i = 0; i < m.fit.parameters.size(); ++i) {
    const auto& n = m.fit.names[i];
    if (block_size[n.block] > 6) {
      if (i == 0 || m.fit.names[i - 1].block != n.block)
        out += fmt::format("             {}: {} parameters (in calibration.json)\n", n.block, block_size[n.block]);
      continue;
    }
    // A frozen parameter has no covariance: "± 0" would claim it exact.
    const double s = m.fit.sigma[i];
    const std::string sigma = s > 0    ? fmt::format("± {:.2g} ", s)
                              : s == 0 ? std::string("(held, not fitted) ")
                                       : std::string("(not identified by the samples) ");
    out += fmt::format("             {}{} = {:.8g} {}{}\n", n.block == "base" ? "" : n.block + ".", n.name,
                       m.fit.parameters[i], sigma, n.unit);
  }
  out += UnidentifiedLine(m.fit);
  const Diagnosis& d = lab.diagnosis;
  const std::string& u = d.reading_unit;  // "raw", or "mm read" for a millimetre sensor
  out += fmt::format("residual     {:.3f} {} rms ({:.2f} mm), held out by pose {:.3f} {} ({:.2f} mm)\n", m.fit.raw.rms,
                     u, m.fit.depth_mm.rms, m.fit.held_out_raw.rms, u, m.fit.held_out_mm.rms);
  out += fmt::format("noise floor  {:.3f} {} from {}; held-out / floor = {:.2f}\n", d.floor.floor_raw, u,
                     d.floor.source, d.ratio_to_floor);
  const Coverage& c = d.coverage;
  out += fmt::format(
      "coverage     {} poses; {} of {} image cells ({:.0f} px) reached by fewer than {} poses ({} by none){}\n",
      c.poses, c.sparse.size() + static_cast<std::size_t>(c.empty_cells), c.poses_per_cell.size(), c.cell_px,
      c.min_poses, c.empty_cells,
      c.under_determined
          ? fmt::format("; {} parameters fit to {:.3f} {} in-sample only", c.parameters, c.in_sample_rms, u)
          : std::string());
  out += "fits         held-out " + u + " rms by model:";
  for (const auto& f : lab.fits) out += fmt::format(" {} {:.3f};", f.name, f.fit.held_out_raw.rms);
  // The best five in full; the rest by name, so that every candidate the
  // time line counts is listed.
  const std::size_t shown = std::min<std::size_t>(d.candidates.size(), 5);
  out += fmt::format("\ncandidates   held-out {} rms with each alone, best {} of {}:", u, shown, d.candidates.size());
  for (std::size_t i = 0; i < shown; ++i) {
    const Candidate& c = d.candidates[i];
    out += c.Fitted() ? fmt::format(" {} {:.3f} ({:+.0f} %, {} of {} poses better, p = {:.2g});", c.name,
                                    c.held_out_rms, -100 * c.reduction, c.poses_better, c.poses_compared, c.p_value)
                      : fmt::format(" {} not fitted: {};", c.name, c.not_fitted);
  }
  if (d.candidates.size() > shown) {
    out += " also";
    for (std::size_t i = shown; i < d.candidates.size(); ++i)
      out += fmt::format(" {}{}", d.candidates[i].name, i + 1 < d.candidates.size() ? "," : " (report.json)");
  }
  out += "\nverdict      " + lab.verdict + "\n";
  return out;
}

}  // namespace speckle
