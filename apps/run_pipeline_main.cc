// run-pipeline SESSION_DIR [--model MODEL.json]: calibrates a session and
// writes a new version under SESSION_DIR/calibrations/.
#include <malloc.h>
#include <algorithm>
#include <map>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <iostream>
#include "apps/cli_main.h"
#include "apps/model_summary.h"

#include "lab/fit/depth_uncertainty.h"
#include "pipeline/artifact_json.h"
#include "pipeline/artifacts.h"
#include "pipeline/assessment.h"
#include "pipeline/calibration_run.h"
#include "pipeline/logged_warnings.h"
#include "pipeline/plausibility_gate.h"
#include "pipeline/report_html.h"
#include "pipeline/run_fingerprint.h"
#include "pipeline/step_seconds.h"
#include "schemas/json_fields.h"
#include "stages/step_clock.h"

namespace {

using namespace speckle;

// Most wall snapshots rejected is a recording to redo, not a detail for
// report.json: said with the commonest reason (an all-floor planar
// recording on wide-angle optics used to end with exit 0 and a count).
std::string WallsWarning(const PipelineResult& p, int planar) {
  const int kept = static_cast<int>(p.snapshots.size());
  if (planar == 0 || 2 * kept >= planar) return "";
  std::map<std::string, int> reasons;
  for (const auto& f : p.frames)
    if (f.recording == "planar" && f.rejection) ++reasons[f.rejection->reason];
  const auto commonest = std::max_element(reasons.begin(), reasons.end(),
                                          [](const auto& a, const auto& b) { return a.second < b.second; });
  return fmt::format(
      "warning      only {} of {} wall snapshots were kept{}. Record the walls again: the sensor square to a "
      "flat wall that fills the view, from near to far\n",
      kept, planar,
      commonest == reasons.end() ? ""
                                 : fmt::format("; {} were rejected because {}", commonest->second, commonest->first));
}

// What the joint calibration refined the cameras from, when it did.
std::string JointLine(const CameraCalibration& cameras) {
  if (!cameras.joint) return "";
  std::string out = "joint        both cameras and the extrinsics refined together from";
  for (std::size_t i = 0; i < cameras.joint->terms.size(); ++i) {
    const auto& t = cameras.joint->terms[i];
    out += fmt::format("{} {} {}{}", i ? "," : "", t.observations, t.kind,
                       t.observations > 0 ? " (" + t.Scatter() + ")" : "");
  }
  if (!cameras.joint->held.empty()) out += fmt::format("; held: {}", fmt::join(cameras.joint->held, ", "));
  return out + "\n";
}

// A camera fitted to no view was given in the session: exact, or a prior of the sigmas it was given with.
std::string GivenCameraText(const CameraIntrinsics& c) {
  if (std::none_of(c.stddev.begin(), c.stddev.end(), [](double s) { return s > 0; })) return "taken as exact";
  return fmt::format("with sigmas (fx ± {:.2f}, fy ± {:.2f}, cx ± {:.2f}, cy ± {:.2f} px), a prior", c.stddev[0],
                     c.stddev[1], c.stddev[2], c.stddev[3]);
}

std::string Summary(const CalibrationRun& run, const std::filesystem::path& version) {
  const PipelineResult& p = run.pipeline;
  std::string out = fmt::format("calibration  {}\n", version.string());
  int planar = 0;
  for (const auto& f : p.frames) planar += f.recording == "planar";
  out += fmt::format(
      "frames       {} of {} depthboard frames {}paired into {} samples; {} of {} planar (wall) frames kept\n",
      p.paired_frames, p.board_frames - p.colour_view_frames, p.colour_view_frames ? "with depth " : "",
      run.lab.samples.size(), p.snapshots.size(), planar);
  // The joint board-plane fit has no reprojection error of its own: its rms
  // (raw units) is in the log, not here.
  const bool plane_fit = p.cameras.depth_intrinsics_source == "joint_board_planes";
  const CameraIntrinsics& colour = p.cameras.colour;
  out += fmt::format("cameras      colour {}; depth intrinsics from {}{}",
                     colour.views > 0 ? fmt::format("rms {:.3f} px", colour.rms_reprojection_px)
                                      : "given in the session, " + GivenCameraText(colour),
                     p.cameras.depth_intrinsics_source,
                     plane_fit ? "\n"
                               : fmt::format("{}; extrinsics rms {:.2f} px over {} views\n",
                                             p.cameras.depth.views > 0
                                                 ? fmt::format(" (rms {:.3f} px)", p.cameras.depth.rms_reprojection_px)
                                                 : ", " + GivenCameraText(p.cameras.depth),
                                             p.cameras.extrinsics_rms_px, p.cameras.extrinsics_views));
  out += JointLine(p.cameras);
  const auto& d = p.cameras.depth;
  if (d.stddev[0] > 0) {
    out +=
        fmt::format("depth camera fx {:.1f} ± {:.1f}, fy {:.1f} ± {:.1f}, cx {:.1f} ± {:.1f}, cy {:.1f} ± {:.1f} px\n",
                    d.camera_matrix(0, 0), d.stddev[0], d.camera_matrix(1, 1), d.stddev[1], d.camera_matrix(0, 2),
                    d.stddev[2], d.camera_matrix(1, 2), d.stddev[3]);
    const bool lens_held = std::all_of(d.stddev.begin() + 4, d.stddev.end(), [](double s) { return s == 0; });
    out += lens_held ? fmt::format(
                           "             lens not fitted: held at k1 {:.3f}, k2 {:.3f}, p1 {:.4f}, p2 {:.4f}, "
                           "k3 {:.3f}\n",
                           d.distortion[0], d.distortion[1], d.distortion[2], d.distortion[3], d.distortion[4])
                     : fmt::format(
                           "             k1 {:.3f} ± {:.3f}, k2 {:.3f} ± {:.3f}, p1 {:.4f} ± {:.4f}, p2 {:.4f} ± "
                           "{:.4f}, k3 {:.3f} ± {:.3f}\n",
                           d.distortion[0], d.stddev[4], d.distortion[1], d.stddev[5], d.distortion[2], d.stddev[6],
                           d.distortion[3], d.stddev[7], d.distortion[4], d.stddev[8]);
  }
  if (!p.cameras.depth_intrinsics_warning.empty())
    out += fmt::format("warning      {}\n", p.cameras.depth_intrinsics_warning);
  out += WallsWarning(p, planar);
  if (p.grid) {
    out +=
        fmt::format("undistortion flat-wall sigma {:+.0f} % (each wall held out)\n", -100 * run.wall_sigma_reduction);
    if (p.grid->method == TrueRawMethod::kOwnPlane) {
      out += fmt::format(
          "             walls tilted up to {:.1f} deg from square to the sensor: each wall's truth is its own\n"
          "             tilted plane, so the distortion's linear part (one wall cannot tell it from a tilt)\n"
          "             is not corrected; walls within 0.5 deg of square would keep it\n",
          p.grid->max_tilt_deg);
    }
  } else if (p.grid_rejection) {
    out += fmt::format("undistortion none: {}\n", p.grid_rejection->reason);
  }
  out += ModelSummary(run.lab);
  out += DepthUncertaintyLine(DepthUncertainty(run.lab.Chosen(), run.lab.ChosenSamples()), p.cameras);
  int rejected = 0, unreadable = 0;
  for (const auto& f : p.frames) {
    rejected += f.rejection.has_value();
    unreadable += f.rejection && f.rejection->stage == "read";
  }
  if (p.colour_view_frames)
    out += fmt::format("colour only  {} board frame(s) without depth: chessboard views for the colour camera alone\n",
                       p.colour_view_frames);
  if (rejected)
    out += fmt::format("rejected     {} frame(s){}; reasons in report.json\n", rejected,
                       unreadable ? fmt::format(", {} of them unreadable (a damaged recording?)", unreadable) : "");
  return out;
}

// How the cameras are fitted: jointly with the model (the default) or in
// separate steps before it.
void AddCameraFlags(CLI::App& app, PipelineOptions& options, bool& separate) {
  app.add_flag("--separate-cameras", separate,
               "fit the colour camera from its chessboards, then the depth camera from the outlines, then the "
               "model with both held (before issue 46's joint calibration; looser: about 1 % of depth at 1 m)");
  app.add_flag("--joint-cameras", options.joint.enabled,
               "refine both cameras, the extrinsics and the model together from every board frame's colour "
               "corners, outline corners and depth samples (the default)")
      ->excludes("--separate-cameras");
  app.add_flag("--judge-beyond-cameras", options.diagnosis.judge_beyond_cameras,
               "judge the model beyond the cameras: candidates fitted with the cameras free within their uncertainty, "
               "complete against the floor without the cameras' part (on trial: issue 46)");
}

}  // namespace

int main(int argc, char** argv) {
  // Raw depth images (600 KB at VGA) go straight to and from the kernel:
  // glibc otherwise raises its mmap threshold past them after the first
  // frees, the graph's images then fill heap arenas that stay mapped, and
  // the fits that follow peaked 70 MB higher at 2000 frames (bench/results/speed.md, Memory).
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
  CLI::App app{
      "Calibrate a session: detect, pair, clean snapshots, build the undistortion grid, fit.\n"
      "Writes a new version SESSION_DIR/calibrations/vNNNN/ and prints a summary."};
  std::string session, model_file;
  int threads = 0, average = 1;
  PipelineOptions options;
  app.add_option("SESSION_DIR", session, "session directory (record-session makes one)")->required();
  app.add_option("--model", model_file, "model spec JSON: base_form, undistortion (auto|on|off), huber_raw, effects");
  app.add_option("--average-still-frames", average,
                 "find each depthboard outline in the median of up to N frames of its still pose (1 = off)")
      ->check(CLI::Range(1, 64));
  app.add_option("--threads", threads, "worker threads (0 = all cores)")->check(CLI::Range(0, 256));
  app.add_option("--held-raw-frames", options.held_raw_frames,
                 "frames that keep their raw depth image in memory between steps; the rest are read again "
                 "(memory: about 0.6 MB a VGA frame)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000000));
  bool separate_cameras = false;
  AddCameraFlags(app, options, separate_cameras);
  bool accept_implausible = false;
  app.add_flag("--accept-implausible", accept_implausible,
               "keep a result no Kinect v1 / PrimeSense sensor gives (focal lengths, principal point, colour rms, "
               "depth scale) as a calibration: for a sensor outside the family; otherwise the run ends with exit 3");
  bool new_version = false;
  app.add_flag("--new-version", new_version,
               "write a new version even when one was made from the same inputs, model and options by this build "
               "(otherwise that version is named and nothing is written)");
  return RunCli("run-pipeline", app, argc, argv, [&] {
    const StepClock clock;
    KeepLoggedWarnings();
    RequireExisting(session, "SESSION_DIR", true);
    RequireExisting(model_file, "--model", false);
    options.refit_tool = ToolBeside(argv[0], "refit");
    const DepthUnits units = ReadSessionManifest(session).depth_units;
    const ModelSpec spec =
        model_file.empty() ? DefaultModelSpec(units) : ModelSpecFromJson(ReadJsonFile(model_file), model_file);
    CheckModelUnits(spec, units, model_file.empty() ? "the default model" : model_file);
    options.threads = threads;
    options.still_frames_averaged = average;
    options.joint.enabled = !separate_cameras;
    const nlohmann::json inputs = SessionInputsJson(session);
    // Threads and held raw frames change the time and memory, not the numbers
    // (Golden.FramesReadAgainGiveTheSameArtifacts); the typed session path
    // and tool name are in the verdict's commands.
    const std::string fingerprint = RunFingerprint({{"verb", "run-pipeline"},
                                                    {"inputs", inputs},
                                                    {"model_spec", ToJson(spec)},
                                                    {"session_as_typed", session},
                                                    {"refit_tool", options.refit_tool},
                                                    {"still_frames_averaged", average},
                                                    {"joint_cameras", options.joint.enabled},
                                                    {"judge_beyond_cameras", options.diagnosis.judge_beyond_cameras},
                                                    {"accept_implausible", accept_implausible}});
    if (const auto same = new_version ? std::nullopt : VersionWithFingerprint(session, fingerprint)) {
      SayUnchanged(*same);
      return kExitOk;
    }
    const CalibrationRun run = RunCalibration(session, options, spec);
    nlohmann::json calibration = CalibrationJson(run, session, inputs), report = ReportJson(run);
    calibration["run_fingerprint"] = fingerprint;
    SetModelJson(run.spec, run.lab, calibration, report);
    MarkPlausibility(calibration, accept_implausible);
    AddAssessment(report, calibration, LoggedWarnings());
    const auto version =
        WriteCalibrationVersion(session, {calibration, report, run.lab.samples, run.perturbations,
                                          run.pipeline.grid ? &*run.pipeline.grid : nullptr, PlotDataJson(run.lab),
                                          run.pipeline.cameras.joint ? &run.pipeline.board_observations : nullptr});
    std::cout << Summary(run, version) << AssessmentLine(report)
              << StepSecondsLine(run.lab, clock.Seconds(), run.pipeline.wall_seconds, run.seconds.camera_perturbations,
                                 run.seconds.wall_hold_outs, std::nullopt);
    EndIfImplausible(version, calibration["plausibility"]);
    return kExitOk;
  });
}
