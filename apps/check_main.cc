// check CALIBRATION RECORDING: is a calibration still good? Scores it on a
// new recording of its sensor (boards, and walls when recorded) and says
// OK, DEGRADED or RECALIBRATE (apps/calibration_check.h says how).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <iostream>
#include <tuple>

#include "apps/calibration_check.h"
#include "apps/check_report.h"
#include "apps/cli_main.h"
#include "apps/depth_sigmas.h"
#include "lab/diagnosis/verdict_text.h"
#include "model/depth_model.h"
#include "pipeline/calibration_graph.h"
#include "pipeline/cameras_json.h"
#include "pipeline/samples_file.h"
#include "recorder/recording_reader.h"
#include "schemas/json_fields.h"
#include "schemas/session_manifest.h"
#include "schemas/staging.h"

namespace {

using namespace speckle;
namespace fs = std::filesystem;

struct Flags {
  std::string calibration, recording, out;
  int threads = 0;
  std::string run_pipeline = "run-pipeline";  // as the user calls it: beside this tool
};

// A standard error from one pose is not known: "-", not "nan".
std::string Shown(double standard_error) {
  return std::isfinite(standard_error) ? fmt::format("{:.2f}", standard_error) : std::string("-");
}

std::string Row(const ErrorCell& c) {
  const std::string judged = std::isfinite(c.z) ? fmt::format("{:4.1f} sigma (of {:.1f})  {}", std::abs(c.z),
                                                              c.threshold_sigmas, ToString(c.verdict))
                                                : "not judged: " + c.not_judged;
  const std::string calibration =
      c.calibration_poses > 0 ? fmt::format("± {:4.2f}", c.fitted_standard_error_raw) : std::string("  none");
  return fmt::format(
      "  {:<13} {:>6} samples {:>3} poses  error {:+5.2f} ± {:4.2f}, calibration's {} ({:>2} poses)  "
      "1 raw = {:4.1f} mm  {}\n",
      c.where, c.samples, c.poses, c.mean_error_raw, c.standard_error_raw, calibration, c.calibration_poses,
      1e3 * c.raw_step_m, judged);
}

void Print(const CheckResult& r) {
  std::cout << fmt::format("boards       {} of {} board frames paired, {} samples\n", r.paired_frames, r.board_frames,
                           r.samples)
            << "by depth     (error in raw units: the calibration's depth minus the board's from its colour pose, "
               "over the depth of one raw value there; ± how well this recording and the calibration's measure it)\n";
  for (const auto& c : r.by_depth) std::cout << Row(c);
  std::cout << "by region\n";
  for (const auto& c : r.by_region) std::cout << Row(c);
  const Registration& g = r.registration;
  if (g.poses == 0)
    std::cout << "registration not judged: " << g.not_judged << "\n";
  else
    std::cout << fmt::format(
        "registration outlines off by ({:+.2f} ± {}, {:+.2f} ± {}) px, grown {:+.2f} ± {} px over {} "
        "poses (calibration ± {:.2f} px); {}\n",
        g.shift_px.x(), Shown(g.shift_standard_error_px.x()), g.shift_px.y(), Shown(g.shift_standard_error_px.y()),
        g.growth_px, Shown(g.growth_standard_error_px), g.poses, g.calibration_sigma_px,
        std::isfinite(g.z) ? fmt::format("{:.1f} sigma, {}", std::abs(g.z), ToString(g.verdict))
                           : "not judged: " + g.not_judged);
  for (const auto& w : r.walls)
    std::cout << fmt::format(
        "wall         frame {} at {:.2f} m: {:.1f} mm rms about its plane; its 3 x 3 regions' "
        "means within {:.1f} mm of it (the largest in the {}); shown, not judged\n",
        w.frame, w.depth_m, 1e3 * w.rms_m, 1e3 * std::abs(w.largest_region_mean_m), w.largest_region);
  std::cout << "judged       " << r.judged << "\n";
  std::cout << "verdict      " << ToString(r.verdict) << "\n";
  for (const auto& why : r.reasons) std::cout << "             " << why << "\n";
}

// The verdict ends with what to do next, as a command that runs when pasted.
void PrintNext(CheckVerdict verdict, const Flags& flags) {
  const std::string recalibrate = ShellWord(flags.run_pipeline) + " " + ShellWord(flags.recording);
  switch (verdict) {
    case CheckVerdict::kOk:
      std::cout << "next         nothing: keep using the calibration\n";
      return;
    case CheckVerdict::kDegraded:
      std::cout << "next         usable, off by less than one raw step; recalibrate when convenient, from this "
                   "recording: "
                << recalibrate << "\n";
      return;
    case CheckVerdict::kRecalibrate:
      std::cout << "next         recalibrate, from this recording: " << recalibrate << "\n";
      return;
    case CheckVerdict::kCannotJudge:
      break;
  }
  std::cout << "next         record boards over the image at the depths you use (docs/tutorial.md), then: check "
            << ShellWord(flags.calibration) << " NEW_RECORDING\n";
}

int ExitCode(CheckVerdict verdict) {
  switch (verdict) {
    case CheckVerdict::kOk:
      return kExitOk;
    case CheckVerdict::kDegraded:
      return kExitDegraded;
    case CheckVerdict::kRecalibrate:
      return kExitRecalibrate;
    case CheckVerdict::kCannotJudge:
      break;
  }
  return kExitCannotJudge;
}

// What check is given as the recording, refused early and by name: a
// calibration in its place (the arguments swapped), or a session with no
// boards to check with.
void RequireRecording(const fs::path& recording) {
  if (!fs::exists(recording / kSessionFileName) &&
      (fs::exists(recording / "calibration.json") || fs::is_directory(recording / "calibrations")))
    throw InputError(recording.string() +
                     ": a calibration, not a recording; check takes CALIBRATION first, then "
                     "RECORDING (a new session of the same sensor)");
}

// A recording of another unit or other optics than the calibration's
// session is said first: every difference check then finds is that.
void WarnAnotherSensor(const fs::path& calibrated_session, const SessionManifest& recording) {
  if (!fs::exists(calibrated_session / kSessionFileName)) return;
  const SessionManifest calibrated = ReadSessionManifest(calibrated_session);
  if (calibrated.optics != recording.optics)
    spdlog::warn(
        "the recording's optics are {}, the calibration's session's {}: another sensor's, not a check of "
        "this one",
        recording.optics, calibrated.optics);
  if (!calibrated.sensor.serial.empty() && !recording.sensor.serial.empty() &&
      calibrated.sensor.serial != recording.sensor.serial)
    spdlog::warn("the recording's sensor serial is {}, the calibration's session's {}: another unit",
                 recording.sensor.serial, calibrated.sensor.serial);
}

// Frames of another size than the calibration's cameras are another
// sensor's (or other optics'): every number check would give is meaningless
// (issue 47's probe: a 1280x1024 recording was judged RECALIBRATE by 2.8 m).
void RefuseOtherImageSizes(const fs::path& recording, const SessionManifest& manifest, const CameraCalibration& cameras,
                           const fs::path& calibration) {
  for (const auto& entry : manifest.recordings) {
    const RecordingHeader header = RecordingReader(recording / entry.file).header();
    for (const auto& [size, camera, name] : {std::tuple{header.colour_size, &cameras.colour, "colour"},
                                             std::tuple{header.depth_size, &cameras.depth, "depth"}}) {
      if (!size || *size == camera->image_size) continue;
      throw InputError(
          fmt::format("{}: its {} images are {}x{}, but the calibration's {} camera ({}) is for {}x{} "
                      "images: a recording of another sensor or other optics cannot check it",
                      (recording / entry.file).string(), name, size->width, size->height, name, calibration.string(),
                      camera->image_size.width, camera->image_size.height));
    }
  }
}

bool HasBoards(const SessionManifest& manifest) {
  for (const auto& r : manifest.recordings)
    if (r.purpose == RecordingPurpose::kDepthboard) return true;
  return false;
}

int Run(const Flags& flags) {
  RequireExisting(flags.recording, "recording session", true);
  RequireRecording(flags.recording);
  if (!flags.out.empty() && fs::exists(NormalizeOutPath(flags.out, "--out")))
    throw InputError(flags.out + ": exists; check overwrites nothing, choose a new --out");
  const fs::path file = CalibrationFile(flags.calibration);
  const apply::DepthCalibration calibration = apply::LoadDepthCalibration(file);
  const apply::DepthSigmaTable sigmas = DepthSigmasOf(file);
  const CameraCalibration cameras = CamerasFromJson(ReadJsonFile(file).at("cameras"), file.string() + ": cameras");
  const SessionManifest manifest = ReadSessionManifest(flags.recording);
  if (manifest.depth_units != calibration.depth_units)
    throw InputError(fmt::format("{}: its depth is in {}, the calibration's ({}) in {}", flags.recording,
                                 ToString(manifest.depth_units), file.string(), ToString(calibration.depth_units)));
  std::cout << fmt::format("check        {} ({})\n             on {}\n", file.string(),
                           calibration.model->Definition().Describe(), flags.recording);
  const fs::path calibrated_session = file.parent_path().parent_path().parent_path();
  WarnAnotherSensor(calibrated_session, manifest);
  RefuseOtherImageSizes(flags.recording, manifest, cameras, file);
  if (!HasBoards(manifest)) {
    std::cout << "verdict      CANNOT JUDGE\n             " << flags.recording
              << " has no depthboard recording: check needs boards (walls alone are not judged)\n";
    PrintNext(CheckVerdict::kCannotJudge, flags);
    return kExitCannotJudge;
  }
  if (fs::exists(calibrated_session / kSessionFileName) && fs::equivalent(calibrated_session, flags.recording))
    spdlog::warn("{} is the calibration's own recording: not a held-out check; record the sensor again",
                 flags.recording);
  PipelineOptions options;
  options.threads = flags.threads;
  options.held_cameras = cameras;
  const PipelineResult recording = RunCalibrationGraph(flags.recording, options);
  std::optional<CachedSamples> own;
  if (fs::exists(file.parent_path() / "samples.h5"))
    own = ReadSamples(file.parent_path() / "samples.h5");
  else
    spdlog::warn("{}: no samples.h5 beside it; the calibration's recording is taken to be like this one",
                 file.string());
  const CheckResult result =
      CheckCalibration({calibration, sigmas, cameras, recording, own ? &own->samples : nullptr}, CheckOptions{});
  Print(result);
  PrintNext(result.verdict, flags);
  std::cout.flush();  // before the log line on stderr
  if (!flags.out.empty()) WriteCheckFolder(flags.out, {file, flags.recording, result});
  return ExitCode(result.verdict);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Score a depth calibration on a new recording of its sensor: OK, DEGRADED or RECALIBRATE."};
  Flags flags;
  app.add_option("CALIBRATION", flags.calibration, "session (its newest version), version folder or calibration.json")
      ->required();
  app.add_option("RECORDING", flags.recording, "a new session of the same sensor: boards, and walls if recorded")
      ->required();
  app.add_option("--out", flags.out, "folder to create with check.json, check.html and the error map");
  app.add_option("--threads", flags.threads, "worker threads (0: all cores)")->check(CLI::Range(0, 256));
  app.footer(
      "Exit codes: 0 OK, 10 DEGRADED, 11 RECALIBRATE, 12 cannot judge (too few boards paired), 2 usage, 3 bad input.");
  flags.run_pipeline = ToolBeside(argv[0], "run-pipeline");
  return RunCli("check", app, argc, argv, [&] { return Run(flags); });
}
