#include "pipeline/step_seconds.h"

#include <fmt/format.h>

#include <algorithm>

namespace speckle {
namespace {

nlohmann::json FitSecondsJson(const NamedFit& f) {
  const FitSeconds& s = f.fit.seconds;
  return {{"name", f.name},
          {"total", s.total},
          {"pre_fit", s.pre_fit},
          {"fit", s.fit},
          {"covariance", s.covariance},
          {"camera_refits", s.camera_refits},
          {"camera_refits_wall", s.camera_refits_wall},
          {"folds", s.folds},
          {"folds_wall", s.folds_wall}};
}

}  // namespace

nlohmann::json ModelStepSecondsJson(const ModelLab& lab) {
  nlohmann::json fits = nlohmann::json::array();
  for (const auto& f : lab.fits) fits.push_back(FitSecondsJson(f));
  const Diagnosis& d = lab.diagnosis;
  nlohmann::json candidates = nlohmann::json::array();
  for (const auto& c : d.candidates) candidates.push_back({{"name", c.name}, {"seconds", c.seconds}});
  return {{"fits", fits},
          {"fits_total", lab.spec_fits_seconds + lab.comparison_fits_seconds},
          {"spec_fits", lab.spec_fits_seconds},
          {"comparison_fits_beside_diagnosis", lab.comparison_fits_seconds},
          {"diagnosis",
           {{"total", d.seconds.total},
            {"residual_analysis", d.seconds.residual_analysis},
            {"current_refit", d.seconds.current_refit},
            {"cameras_free", d.seconds.cameras_free},
            {"candidates_wall", d.seconds.candidates},
            {"candidates", candidates},
            {"pairs_wall", d.seconds.pairs}}},
          {"model_lab", lab.seconds}};
}

nlohmann::json RunStepSecondsJson(const CalibrationRun& run) {
  nlohmann::json walls = nlohmann::json::array();
  for (const auto& w : run.walls) walls.push_back({{"frame", w.snapshot_frame}, {"seconds", w.seconds}});
  return {{"graph", run.pipeline.wall_seconds},
          {"camera_perturbations", run.seconds.camera_perturbations},
          {"wall_hold_outs", {{"total", run.seconds.wall_hold_outs}, {"walls", walls}}},
          {"total", run.seconds.total}};
}

std::string StepSecondsLine(const ModelLab& lab, double total_seconds, std::optional<double> graph_seconds,
                            std::optional<double> perturbation_seconds, std::optional<double> wall_seconds,
                            std::optional<double> reading_seconds) {
  std::string out = fmt::format("time         {:.1f} s:", total_seconds);
  if (reading_seconds) out += fmt::format(" reading samples {:.1f} s,", *reading_seconds);
  if (graph_seconds) out += fmt::format(" graph {:.1f} s,", *graph_seconds);
  // The joint calibration, or the separate cameras' perturbations.
  if (perturbation_seconds) out += fmt::format(" cameras {:.1f} s,", *perturbation_seconds);
  // The comparison fits run beside the diagnosis (model_lab.cc): the line
  // says so, so that its parts add up to the total.
  out += fmt::format(" {} fits {:.1f} s, then diagnosis {:.1f} s", lab.spec_fits, lab.spec_fits_seconds,
                     lab.diagnosis.seconds.total);
  const auto& candidates = lab.diagnosis.candidates;
  const auto slowest = std::max_element(candidates.begin(), candidates.end(),
                                        [](const Candidate& a, const Candidate& b) { return a.seconds < b.seconds; });
  if (slowest != candidates.end())
    out += fmt::format(" ({} candidates side by side, slowest {} {:.1f} s)", candidates.size(), slowest->name,
                       slowest->seconds);
  const std::size_t comparisons = lab.fits.size() - static_cast<std::size_t>(lab.spec_fits);
  if (comparisons > 0)
    out += fmt::format(" with {} comparison fits {:.1f} s beside it", comparisons, lab.comparison_fits_seconds);
  if (wall_seconds) out += fmt::format(", wall hold-outs {:.1f} s", *wall_seconds);
  return out + "; per step in report.json step_seconds\n";
}

}  // namespace speckle
