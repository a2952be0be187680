#include "pipeline/artifact_json.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "lab/fit/depth_uncertainty.h"
#include "pipeline/sha256_file.h"
#include "pipeline/step_seconds.h"
#include "schemas/artifact_schema.h"
#include "schemas/atomic_file.h"
#include "schemas/decimal_text.h"
#include "schemas/json_fields.h"
#include "schemas/session_manifest.h"
#include "speckle/tool_version.h"

namespace speckle {
namespace {

namespace fs = std::filesystem;

nlohmann::json StatsJson(const ResidualStats& s) {
  return {{"count", s.count}, {"mean", s.mean}, {"sigma", s.sigma}, {"rms", s.rms},
          {"p05", s.p05},     {"p50", s.p50},   {"p95", s.p95},     {"max_abs", s.max_abs}};
}

// The camera's covariance with its diagonal the sigmas it states (a step
// after the fit may have widened a sigma: the IR recording's), the terms'
// correlations kept; null where the fit stated none.
nlohmann::json CovarianceJson(const CameraIntrinsics& c) {
  if (c.covariance.size() != 81) return nullptr;
  std::array<double, 9> scale{};
  for (std::size_t i = 0; i < 9; ++i)
    scale[i] = c.covariance[10 * i] > 0 ? c.stddev[i] / std::sqrt(c.covariance[10 * i]) : 0.0;
  std::vector<double> out(81);
  for (std::size_t i = 0; i < 9; ++i)
    for (std::size_t j = 0; j < 9; ++j) out[9 * i + j] = c.covariance[9 * i + j] * scale[i] * scale[j];
  for (std::size_t i = 0; i < 9; ++i)  // a sigma the fit held but a later step states
    if (!(c.covariance[10 * i] > 0)) out[10 * i] = c.stddev[i] * c.stddev[i];
  return out;
}

nlohmann::json IntrinsicsJson(const CameraIntrinsics& c) {
  return {{"image_size", {c.image_size.width, c.image_size.height}},
          {"fx", c.camera_matrix(0, 0)},
          {"fy", c.camera_matrix(1, 1)},
          {"cx", c.camera_matrix(0, 2)},
          {"cy", c.camera_matrix(1, 2)},
          {"distortion_k1_k2_p1_p2_k3", c.distortion},
          {"stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3", c.stddev},
          // Row-major 9 x 9 in the same order; null where the fit stated only the sigmas.
          {"covariance_fx_fy_cx_cy_k1_k2_p1_p2_k3", CovarianceJson(c)},
          {"rms_reprojection_px", c.rms_reprojection_px},
          {"views", c.views}};
}

// The depth camera's; a joint board-plane fit has no reprojection error.
nlohmann::json DepthIntrinsicsJson(const CameraCalibration& cameras) {
  nlohmann::json depth = IntrinsicsJson(cameras.depth);
  if (cameras.depth_intrinsics_source == "joint_board_planes") depth["rms_reprojection_px"] = nullptr;
  return depth;
}

// The joint calibration's account, or null when the separate steps' cameras were kept.
nlohmann::json JointJson(const CameraCalibration& cameras) {
  if (!cameras.joint) return nullptr;
  nlohmann::json terms = nlohmann::json::array();
  for (const auto& t : cameras.joint->terms)
    terms.push_back({{"kind", t.kind},
                     {"observations", t.observations},
                     {"rms", t.observations > 0 ? nlohmann::json(t.rms) : nlohmann::json(nullptr)},
                     {"unit", t.unit}});
  return {{"terms", terms},
          {"held", cameras.joint->held},
          {"iterations", cameras.joint->iterations}};  // its time is report.json's step_seconds
}

// Null where no fit bounded the translation (all zero).
nlohmann::json TranslationSigmaJson(const CameraCalibration& cameras) {
  const Eigen::Vector3d& sigma = cameras.extrinsics_translation_sigma_m;
  return sigma.isZero() ? nlohmann::json(nullptr) : nlohmann::json(sigma);
}

nlohmann::json FitJson(const NamedFit& f) {
  // A parameter the samples do not identify has no honest sigma: null.
  const auto sigma = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json parameters = nlohmann::json::array();
  for (std::size_t i = 0; i < f.fit.parameters.size(); ++i) {
    const auto& n = f.fit.names[i];
    const bool identified =
        std::find(f.fit.unidentified.begin(), f.fit.unidentified.end(), i) == f.fit.unidentified.end();
    parameters.push_back({{"block", n.block},
                          {"name", n.name},
                          {"unit", n.unit},
                          {"value", f.fit.parameters[i]},
                          {"identified", identified},
                          {"sigma", sigma(f.fit.sigma[i])},
                          {"sigma_from_samples", sigma(f.fit.sigma_samples[i])},
                          {"sigma_from_cameras", sigma(f.fit.sigma_cameras[i])}});
  }
  nlohmann::json effects = nlohmann::json::array();
  for (const auto& e : f.fit.definition.effects) effects.push_back(model::ToJson(e));
  return {{"name", f.name},
          {"base_form", model::Info(f.fit.definition.form).name},
          {"effects", effects},
          {"undistortion", f.undistorted},
          {"parameters", parameters},
          {"covariance", f.fit.covariance},
          {"converged", f.fit.converged},
          {"residual_raw", StatsJson(f.fit.raw)},
          {"residual_mm", StatsJson(f.fit.depth_mm)},
          {"held_out_raw", StatsJson(f.fit.held_out_raw)},
          {"held_out_mm", StatsJson(f.fit.held_out_mm)}};
}

nlohmann::json CovariatesJson(const Diagnosis& d) {
  nlohmann::json covariates = nlohmann::json::array();
  for (const auto& c : d.covariates) {
    covariates.push_back(
        {{"covariate", c.covariate},
         {"unit", c.unit},
         {"level", c.level},
         {"explained_share", c.explained_share},
         {"significance", std::isfinite(c.significance) ? nlohmann::json(c.significance) : nlohmann::json(nullptr)},
         {"p_value", c.p_value},
         {"bin_centre", c.bin_centre},
         {"bin_mean_raw", c.bin_mean},
         {"bin_count", c.bin_count}});
  }
  return covariates;
}

nlohmann::json CandidatesJson(const Diagnosis& d) {
  nlohmann::json candidates = nlohmann::json::array();
  for (const auto& c : d.candidates) {
    // A candidate that was not fitted has no numbers: null, and why.
    const auto number = [&](double v) { return c.Fitted() ? nlohmann::json(v) : nlohmann::json(nullptr); };
    candidates.push_back(
        {{"name", c.name},
         {"doc", c.doc},
         {"reads", c.reads},
         {"held_out_raw", number(c.held_out_rms)},
         {"held_out_mm", number(c.held_out_mm)},
         {"held_out_raw_interval",
          c.held_out_interval_raw ? nlohmann::json({c.held_out_interval_raw->first, c.held_out_interval_raw->second})
                                  : nlohmann::json(nullptr)},
         {"reduction", number(c.reduction)},
         {"significance", number(c.significance)},
         {"reduction_beyond_cameras", number(c.reduction_beyond_cameras)},
         {"significance_beyond_cameras", number(c.significance_beyond_cameras)},
         {"p_value", number(c.p_value)},
         {"p_value_beyond_cameras", number(c.p_value_beyond_cameras)},
         {"poses_better", c.poses_better},
         {"poses_compared", c.poses_compared},
         {"parameters", c.parameters},
         {"held_out_jointly", c.held_out_jointly},
         {"recommended", c.recommended},
         {"not_fitted", c.Fitted() ? nlohmann::json(nullptr) : nlohmann::json(c.not_fitted)}});
  }
  return candidates;
}

nlohmann::json NoiseFloorJson(const NoiseFloor& f) {
  return {{"floor_raw", f.floor_raw},
          {"source", f.source},
          {"quantization_raw", f.quantization_raw},
          {"consecutive_frames_raw",
           f.consecutive_frames_raw > 0 ? nlohmann::json(f.consecutive_frames_raw) : nlohmann::json(nullptr)},
          {"consecutive_pairs", f.consecutive_pairs},
          {"sensor_raw", f.sensor_raw},
          {"colour_pose_raw", f.colour_pose_raw > 0 ? nlohmann::json(f.colour_pose_raw) : nlohmann::json(nullptr)},
          {"cameras_raw", f.cameras_raw > 0 ? nlohmann::json(f.cameras_raw) : nlohmann::json(nullptr)},
          {"grid_raw", f.grid_raw > 0 ? nlohmann::json(f.grid_raw) : nlohmann::json(nullptr)},
          {"neighbour_pixels_raw",
           f.neighbour_pixels_raw > 0 ? nlohmann::json(f.neighbour_pixels_raw) : nlohmann::json(nullptr)},
          {"neighbour_corners_raw",
           f.neighbour_corners_raw > 0 ? nlohmann::json(f.neighbour_corners_raw) : nlohmann::json(nullptr)}};
}

nlohmann::json CoverageJson(const Coverage& c) {
  nlohmann::json poses_per_cell = nlohmann::json::array(), sparse = nlohmann::json::array();
  for (int v = 0; v < c.cells_v; ++v)
    poses_per_cell.push_back(
        std::vector<int>(c.poses_per_cell.begin() + v * c.cells_u, c.poses_per_cell.begin() + (v + 1) * c.cells_u));
  for (const auto& cell : c.sparse)
    sparse.push_back({{"u0", cell.u0}, {"v0", cell.v0}, {"u1", cell.u1}, {"v1", cell.v1}, {"poses", cell.poses}});
  return {{"cell_px", c.cell_px},       {"min_poses_per_cell", c.min_poses}, {"poses_per_cell", poses_per_cell},
          {"sparse_cells", sparse},     {"empty_cells", c.empty_cells},      {"poses", c.poses},
          {"parameters", c.parameters}, {"in_sample_raw", c.in_sample_rms},  {"under_determined", c.under_determined}};
}

nlohmann::json DiagnosisJson(const ModelLab& lab) {
  const Diagnosis& d = lab.diagnosis;
  return {{"noise_floor", NoiseFloorJson(d.floor)},
          {"held_out_raw", d.held_out_rms},
          {"held_out_mm", d.held_out_mm},
          {"ratio_to_floor", d.ratio_to_floor},
          {"complete", d.complete},
          {"judged_jointly", d.judged_jointly},
          {"joint_declined", d.joint_declined.empty() ? nlohmann::json(nullptr) : nlohmann::json(d.joint_declined)},
          {"coverage", CoverageJson(d.coverage)},
          {"covariates", CovariatesJson(d)},
          {"candidates", CandidatesJson(d)},
          {"cameras_free",
           {{"held_out_raw",
             d.cameras_free_held_out_rms ? nlohmann::json(*d.cameras_free_held_out_rms) : nlohmann::json(nullptr)},
            {"shift_sigma", d.camera_shift_sigma}}},
          {"test", {{"description", d.test}, {"poses", d.test_poses}, {"poses_needed", d.poses_needed}}},
          {"recommended", d.recommended ? nlohmann::json(*d.recommended) : nlohmann::json(nullptr)},
          {"borderline", d.borderline.empty() ? nlohmann::json(nullptr) : nlohmann::json(d.borderline)},
          {"best_pair", d.best_pair ? nlohmann::json{{"with", d.recommended.value_or("")},
                                                     {"second", d.best_pair->second},
                                                     {"held_out_raw", d.best_pair->held_out_rms},
                                                     {"reduction_over_single", d.best_pair->reduction_over_single},
                                                     {"p_value", d.best_pair->p_value},
                                                     {"poses_better", d.best_pair->poses_better},
                                                     {"poses_compared", d.best_pair->poses_compared}}
                                    : nlohmann::json(nullptr)},
          {"named_covariate", d.named_covariate.empty() ? nlohmann::json(nullptr) : nlohmann::json(d.named_covariate)},
          {"formula_hint", d.formula_hint},
          {"conclusion", ConclusionName(d.conclusion)},
          {"next_steps", lab.next_steps},
          {"verdict", lab.verdict}};
}

nlohmann::json DepthUncertaintyJson(const NamedFit& f, const std::vector<PairedSample>& samples) {
  nlohmann::json rows = nlohmann::json::array();
  for (const DepthSigma& r : DepthUncertainty(f, samples))
    rows.push_back(
        {{"raw", r.raw}, {"depth_m", r.depth_m}, {"sigma_mm", r.sigma_mm}, {"extrapolated", r.extrapolated}});
  return rows;
}

}  // namespace

nlohmann::json CamerasJson(const CameraCalibration& c) {
  const Eigen::Isometry3d& e = c.depth_from_colour;
  const Eigen::AngleAxisd rotation(e.linear());
  return {{"colour", IntrinsicsJson(c.colour)},
          {"depth", DepthIntrinsicsJson(c)},
          {"depth_intrinsics_source", c.depth_intrinsics_source},
          {"joint", JointJson(c)},
          {"depth_intrinsics_warning",
           c.depth_intrinsics_warning.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.depth_intrinsics_warning)},
          {"depth_edge_offset_px",
           c.depth_edge_offset_px ? nlohmann::json(*c.depth_edge_offset_px) : nlohmann::json(nullptr)},
          {"depth_from_colour",
           {{"rotation_axis_angle_rad", rotation.axis() * rotation.angle()},
            {"translation_m", e.translation()},
            {"translation_sigma_m", TranslationSigmaJson(c)},
            {"outline_rms_px", c.depth_intrinsics_source == "joint_board_planes" ? nlohmann::json(nullptr)
                                                                                 : nlohmann::json(c.extrinsics_rms_px)},
            {"depth_delay_s", c.depth_delay_s ? nlohmann::json(*c.depth_delay_s) : nlohmann::json(nullptr)},
            {"views", c.extrinsics_views}}}};
}

nlohmann::json SessionInputsJson(const fs::path& session_dir) {
  nlohmann::json inputs = nlohmann::json::array();
  const SessionManifest manifest = ReadSessionManifest(session_dir);
  inputs.push_back({{"file", kSessionFileName}, {"sha256", Sha256File(session_dir / kSessionFileName)}});
  for (const auto& r : manifest.recordings) {
    // As session-info says it (the hash's own message named no recording).
    if (!fs::exists(session_dir / r.file))
      throw InputError((session_dir / r.file).string() + ": no such recording file (session.json lists it)");
    inputs.push_back(
        {{"file", r.file}, {"purpose", ToString(r.purpose)}, {"sha256", Sha256File(session_dir / r.file)}});
  }
  return inputs;
}

nlohmann::json CalibrationJson(const CalibrationRun& run, const fs::path& session_dir, const nlohmann::json& inputs) {
  const PipelineResult& p = run.pipeline;
  nlohmann::json calibration = {
      {"schema", "speckle.calibration"},
      {"schema_version", kCalibrationSchemaVersion},
      {"tool_version", kToolVersion},
      {"created_utc", UtcNowIso8601()},
      {"session", {{"path", fs::absolute(session_dir).string()}, {"inputs", inputs}}},
      {"parent_version", nullptr},
      {"samples", "samples.h5"},
      {"cameras", CamerasJson(p.cameras)},
      {"metrics",
       {{"samples", run.lab.samples.size()},
        {"board_frames", p.board_frames},
        {"paired_frames", p.paired_frames},
        {"colour_view_frames", p.colour_view_frames},
        // Of the board frames that have a depth image: a colour-only view
        // has nothing to pair.
        {"paired_share", p.board_frames > p.colour_view_frames
                             ? double(p.paired_frames) / (p.board_frames - p.colour_view_frames)
                             : 0.0},
        {"wall_sigma_reduction", run.wall_sigma_reduction}}},
  };
  return calibration;
}

void SetModelJson(const ModelSpec& spec, const ModelLab& lab, nlohmann::json& calibration, nlohmann::json& report) {
  const NamedFit& chosen = lab.Chosen();
  calibration["model_spec"] = ToJson(spec);
  calibration["model"] = FitJson(chosen);
  calibration["undistortion_grid"] =
      chosen.undistorted ? nlohmann::json("undistortion_grid.h5") : nlohmann::json(nullptr);
  nlohmann::json& metrics = calibration["metrics"];
  metrics["residual_raw"] = StatsJson(chosen.fit.raw);
  metrics["residual_mm"] = StatsJson(chosen.fit.depth_mm);
  metrics["held_out_raw"] = StatsJson(chosen.fit.held_out_raw);
  metrics["held_out_mm"] = StatsJson(chosen.fit.held_out_mm);
  metrics["noise_floor_raw"] = lab.diagnosis.floor.floor_raw;
  metrics["held_out_to_floor"] = lab.diagnosis.ratio_to_floor;
  nlohmann::json fits = nlohmann::json::array();
  for (const auto& f : lab.fits) fits.push_back(FitJson(f));
  report["chosen_model"] = chosen.name;
  report["fits"] = fits;
  report["diagnosis"] = DiagnosisJson(lab);
  report["depth_uncertainty"] = DepthUncertaintyJson(chosen, lab.ChosenSamples());
  // The model's steps join (or, for a refit, replace) the run's.
  if (!report.contains("step_seconds") || !report["step_seconds"].is_object())
    report["step_seconds"] = nlohmann::json::object();
  report["step_seconds"].update(ModelStepSecondsJson(lab));
}

// A wall mask as run lengths over its sampled grid (report schema 7); the
// reading runs (schema 14) tell floor, ceiling and clutter from no reading.
nlohmann::json WallMaskJson(const WallMask& mask) {
  return {{"crop_px", mask.crop_px}, {"stride", mask.stride},     {"cols", mask.cols},
          {"rows", mask.rows},       {"runs", mask.RunLengths()}, {"reading_runs", mask.ReadingRunLengths()}};
}

namespace {

// The board's size by the depth's triangulation (stages/board_size_in_depth.h).
nlohmann::json BoardSizeJson(const std::optional<BoardSizeInDepth>& size) {
  if (!size) return nullptr;
  return {{"measured_m", size->measured_m}, {"sigma_m", size->sigma_m}, {"stated_m", size->stated_m},
          {"ratio", size->Ratio()},         {"views", size->views},     {"outside_family", size->OutsideFamily()}};
}

}  // namespace

nlohmann::json ReportJson(const CalibrationRun& run) {
  const PipelineResult& p = run.pipeline;
  std::map<std::string, int> rejection_counts;
  std::vector<double> edge_rms;
  nlohmann::json frames = nlohmann::json::array();
  for (const auto& f : p.frames) {
    nlohmann::json j = {{"recording", f.recording}, {"index", f.index},     {"source_number", f.source_number},
                        {"pose", f.pose},           {"samples", f.samples}, {"colour_view", f.colour_view}};
    if (f.quad_edge_rms_px) j["quad_edge_rms_px"] = *f.quad_edge_rms_px, edge_rms.push_back(*f.quad_edge_rms_px);
    if (f.rejection) {
      j["rejected_by"] = f.rejection->stage;
      j["reason"] = f.rejection->reason;
      if (f.rejected_wall) j["wall_mask"] = WallMaskJson(*f.rejected_wall);
      ++rejection_counts[f.recording + " / " + f.rejection->stage + ": " + f.rejection->reason];
    }
    frames.push_back(j);
  }
  nlohmann::json rejections = nlohmann::json::array();
  for (const auto& [reason, count] : rejection_counts) rejections.push_back({{"reason", reason}, {"frames", count}});
  nlohmann::json snapshots = nlohmann::json::array();
  for (const auto& s : p.snapshots) {
    snapshots.push_back({{"frame", s.frame},
                         {"valid_pixels", s.valid_pixels},
                         {"inlier_pixels", s.inlier_pixels},
                         {"true_raw",
                          {{"image_minimum", s.true_raw_image_min},
                           {"hyperboloid", s.true_raw_hyperboloid},
                           {"centre_minimum", s.true_raw_centre_min}}},
                         {"fit_sigma_raw", s.fit_sigma_raw},
                         {"raw_sigma", s.raw_sigma_before},
                         {"tilt_deg", s.tilt_deg},
                         {"tilt_verdict", s.tilt_verdict},
                         {"wall_share", s.wall_share},
                         {"wall_mask", WallMaskJson(s.mask)}});
  }
  nlohmann::json walls = nlohmann::json::array();
  for (const auto& w : run.walls) {
    walls.push_back({{"frame", w.snapshot_frame},
                     {"true_raw", w.true_raw},
                     {"sigma_before_raw", w.sigma_before},
                     {"sigma_after_raw_held_out", w.sigma_after}});
  }
  nlohmann::json timings = nlohmann::json::array();
  for (const auto& t : p.timings) timings.push_back({{"stage", t.stage}, {"seconds", t.seconds}, {"calls", t.calls}});
  return {
      {"schema", "speckle.report"},
      {"schema_version", kReportSchemaVersion},
      {"tool_version", kToolVersion},
      {"frames", frames},
      {"rejections", rejections},
      {"depthboard_quads",
       {{"still_frames_averaged", p.still_frames_averaged},
        {"found", edge_rms.size()},
        {"median_edge_rms_px", edge_rms.empty() ? nlohmann::json(nullptr) : nlohmann::json(Summarize(edge_rms).p50)},
        {"board_size_in_depth", BoardSizeJson(p.board_size_in_depth)}}},
      {"planar_snapshots", snapshots},
      {"undistortion", p.grid ? nlohmann::json{{"supported_share", p.grid->SupportedShare()},
                                               {"true_raw_method", ToString(p.grid->method)},
                                               {"max_wall_tilt_deg", p.grid->max_tilt_deg},
                                               {"wall_sigma_reduction_held_out", run.wall_sigma_reduction},
                                               {"walls", walls}}
                              : nlohmann::json{{"absent_because", p.grid_rejection ? p.grid_rejection->reason : ""}}},
      {"stage_seconds", timings},
      {"wall_seconds", p.wall_seconds},
      {"step_seconds", RunStepSecondsJson(run)},
  };
}

}  // namespace speckle
