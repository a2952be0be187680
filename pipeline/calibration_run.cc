#include "pipeline/calibration_run.h"

#include <numeric>

#include "schemas/errors.h"

namespace speckle {

CalibrationRun RunCalibration(const std::filesystem::path& session_dir, const PipelineOptions& options,
                              const ModelSpec& spec) {
  CalibrationRun run;
  run.spec = spec;
  run.pipeline = RunCalibrationGraph(session_dir, options);
  const PipelineResult& p = run.pipeline;
  if (p.samples.empty()) {
    std::map<std::string, int> reasons;
    for (const auto& f : p.frames)
      if (f.rejection) ++reasons[f.rejection->stage + ": " + f.rejection->reason];
    std::string why;
    for (const auto& [reason, count] : reasons) why += "\n  " + std::to_string(count) + " x " + reason;
    throw InputError(session_dir.string() + ": no depthboard frame could be paired, so there is nothing to fit" + why);
  }
  if (p.grid) {
    run.undistorted_samples = p.samples;
    for (auto& s : run.undistorted_samples) s.raw = p.grid->Apply(s.raw, s.x, s.y);
  }
  std::vector<model::BaseForm> forms = {model::BaseForm::kReciprocal, model::BaseForm::kTangent,
                                        model::BaseForm::kDisparity};
  for (model::BaseForm form : forms) {
    for (bool undistorted : {false, true}) {
      if (undistorted && !p.grid) continue;
      DepthFitOptions fit_options;
      fit_options.form = form;
      fit_options.huber_raw = spec.huber_raw;
      // Depths come from colour poses: their scale is as uncertain as the
      // colour camera's focal length.
      const auto& sd = p.cameras.colour.stddev;
      const auto& k = p.cameras.colour.camera_matrix;
      fit_options.depth_scale_sigma = 0.5 * (sd[0] / k(0, 0) + sd[1] / k(1, 1));
      auto fit = RunDepthModelFit(fit_options, undistorted ? run.undistorted_samples : p.samples);
      if (!Accepted(fit)) continue;
      run.fits.push_back({std::string(model::Info(form).name) + (undistorted ? "+undistortion" : ""), undistorted,
                          std::get<DepthFit>(fit)});
    }
  }
  if (run.fits.empty()) throw InputError(session_dir.string() + ": too few paired samples to fit any depth model");
  // The chosen model: the spec's base form, with the grid as the spec says.
  int without = -1, with = -1;
  for (int i = 0; i < static_cast<int>(run.fits.size()); ++i) {
    if (run.fits[i].fit.form != spec.base_form) continue;
    (run.fits[i].undistorted ? with : without) = i;
  }
  if (without < 0) throw InputError("the " + std::string(model::Info(spec.base_form).name) + " form could not be fitted");
  run.chosen = without;
  if (with >= 0 && (spec.undistortion == UndistortionUse::kOn ||
                    (spec.undistortion == UndistortionUse::kAuto &&
                     run.fits[with].fit.held_out_raw.rms < run.fits[without].fit.held_out_raw.rms))) {
    run.chosen = with;
  }

  // Flat walls before and after undistortion, each wall corrected by a grid
  // that never saw it.
  if (p.grid && p.snapshots.size() >= 3) {
    double before = 0, after = 0;
    for (std::size_t held = 0; held < p.snapshots.size(); ++held) {
      std::vector<PlanarSnapshot> others;
      for (std::size_t k = 0; k < p.snapshots.size(); ++k)
        if (k != held) others.push_back(p.snapshots[k]);
      const auto grid = RunUndistortionGridBuild(options.grid, others);
      if (!Accepted(grid)) continue;
      const auto& g = std::get<UndistortionGrid>(grid);
      const PlanarSnapshot& s = p.snapshots[held];
      double sum = 0, sum_sq = 0;
      for (const auto& px : s.inliers) {
        const double r = g.Apply(px.raw, px.x, px.y);
        sum += r, sum_sq += r * r;
      }
      const double n = static_cast<double>(s.inliers.size());
      const double sigma_after = std::sqrt(std::max(0.0, sum_sq / n - (sum / n) * (sum / n)));
      run.walls.push_back({s.frame, s.TrueRaw(options.grid.method), s.raw_sigma_before, sigma_after});
      before += s.raw_sigma_before, after += sigma_after;
    }
    if (before > 0) run.wall_sigma_reduction = 1 - after / before;
  }
  return run;
}

}  // namespace speckle
