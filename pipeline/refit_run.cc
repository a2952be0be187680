#include "pipeline/refit_run.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "apply/depth_calibration.h"
#include "apply/depth_calibration_json.h"
#include "apply/plausibility.h"
#include "apply/undistortion_grid_file.h"
#include "pipeline/artifact_json.h"
#include "pipeline/artifacts.h"
#include "pipeline/assessment.h"
#include "pipeline/cameras_json.h"
#include "pipeline/joint_cameras.h"
#include "pipeline/logged_warnings.h"
#include "pipeline/parent_version.h"
#include "pipeline/plausibility_gate.h"
#include "pipeline/refit_costs.h"
#include "pipeline/report_html.h"
#include "pipeline/run_fingerprint.h"
#include "pipeline/samples_file.h"
#include "pipeline/sha256_file.h"
#include "pipeline/steps/camera_step.h"
#include "pipeline/unseen_regions.h"
#include "schemas/atomic_file.h"
#include "schemas/calibration_versions.h"
#include "schemas/errors.h"
#include "schemas/json_fields.h"
#include "schemas/session_manifest.h"
#include "speckle/tool_version.h"
#include "stages/step_clock.h"

namespace speckle {
namespace {

namespace fs = std::filesystem;

// Whether the new model did better than the one it started from: the same
// samples, held out by the same poses, so the two errors compare directly.
std::string AgainstParentLine(const std::string& parent_name, const nlohmann::json& parent_calibration,
                              const ModelLab& lab) {
  const nlohmann::json& held_out = parent_calibration["metrics"]["held_out_raw"]["rms"];
  if (!held_out.is_number()) return {};
  const double before = held_out.get<double>(), after = lab.Chosen().fit.held_out_raw.rms;
  return fmt::format("against      {} ({}): held-out {:.3f} -> {:.3f} {} ({:+.1f} %)\n", parent_name,
                     parent_calibration["model"].value("name", std::string("?")), before, after,
                     lab.diagnosis.reading_unit, 100 * (after / before - 1));
}

// The parent's verdict promised the effect this refit adds: its promise
// against what the refit achieved, so a user sees whether the promise held.
std::string PromiseLine(const std::string& parent_name, const nlohmann::json& parent_report,
                        const RefitOptions& options, const ModelLab& lab) {
  if (options.add_effects.size() != 1 || !options.model_file.empty() || !options.base_form.empty()) return {};
  for (const auto& c : parent_report.value("/diagnosis/candidates"_json_pointer, nlohmann::json::array())) {
    const nlohmann::json interval = c.value("held_out_raw_interval", nlohmann::json());
    if (!c.value("recommended", false) || c.value("name", std::string()) != options.add_effects[0] ||
        !interval.is_array() || !c.value("held_out_raw", nlohmann::json()).is_number())
      continue;
    const double low = interval[0].get<double>(), high = interval[1].get<double>();
    const double achieved = lab.Chosen().fit.held_out_raw.rms;
    return fmt::format(
        "promised     {}'s verdict: about {:.3f} {u} (90 % interval {:.3f}-{:.3f} over poses); "
        "achieved {:.3f}, {}\n",
        parent_name, c["held_out_raw"].get<double>(), low, high, achieved,
        achieved < low    ? "below it: better than promised (the promise was held out on the candidates' subsample "
                            "and folds)"
        : achieved > high ? "above it: worse than promised (the promise was held out on the candidates' subsample "
                            "and folds)"
                          : "inside it",
        fmt::arg("u", lab.diagnosis.reading_unit));
  }
  return {};
}

// --from names one of this session's versions, nothing else: a path to
// another session's version became this session's newest, which
// apply-calibration then used by default.
fs::path ParentVersionDir(const RefitOptions& options) {
  if (options.from.empty())
    return NewestCalibrationVersion(options.session, "nothing to refit: run run-pipeline first");
  std::string existing;
  for (const fs::path& version : CalibrationVersions(options.session)) {
    if (version.filename() == options.from) return version;
    existing += (existing.empty() ? "" : ", ") + version.filename().string();
  }
  throw InputError("--from " + options.from + ": no such version of " + options.session +
                   (existing.empty() ? " (it has none)" : " (it has " + existing + ")"));
}

// A version copied in from another session (its folder, or a symlink to it)
// lists the recordings that made it: each must be this session's, byte for
// byte, or the refit would make another session's calibration this one's newest.
void RequireThisSessionsRecordings(const fs::path& parent, const nlohmann::json& calibration,
                                   const std::string& session) {
  const nlohmann::json inputs =
      calibration.value("session", nlohmann::json::object()).value("inputs", nlohmann::json::array());
  for (const auto& input : inputs) {
    if (!input.is_object() || !input.contains("purpose")) continue;  // session.json may change (--add-to)
    const std::string file = input.value("file", "");
    const fs::path here = fs::path(session) / file;
    if (fs::is_regular_file(here) && Sha256File(here) == input.value("sha256", "")) continue;
    throw InputError(
        fmt::format("{}: made from another session's recordings ({} {} here); a version belongs to the "
                    "session whose recordings made it",
                    parent.string(), file, fs::exists(here) ? "differs from the one" : "is not"));
  }
}

// The model to fit: the parent's spec or the model file, with the added
// effects and the base form asked for. The verdict's "refit --add-effect X" is the current model with X,
// and the current model's grid choice is part of it: the candidate was
// judged on the samples that choice gave. Left to "auto" the refit chose
// again and could drop the grid it was promised with (Herrera's pattern:
// promised 1.128 raw with the grid, refit without it at 1.195).
ModelSpec SpecToFit(const RefitOptions& options, const fs::path& parent, const nlohmann::json& calibration) {
  ModelSpec spec =
      options.model_file.empty()
          ? ModelSpecFromJson(calibration.at("model_spec"), (parent / "calibration.json").string() + ": model_spec")
          : ModelSpecFromJson(ReadJsonFile(options.model_file), options.model_file);
  if ((!options.add_effects.empty() || !options.base_form.empty()) && options.model_file.empty())
    spec.undistortion = calibration.value("undistortion_grid", nlohmann::json()).is_string() ? UndistortionUse::kOn
                                                                                             : UndistortionUse::kOff;
  if (!options.base_form.empty()) {
    try {
      spec.base_form = model::BaseFormFromName(options.base_form);
    } catch (const InputError& e) {
      throw UsageError(std::string("--base-form: ") + e.what());
    }
  }
  for (const std::string& name : options.add_effects) {
    for (const auto& e : spec.effects)
      if (e.name == name) throw InputError("--add-effect " + name + ": the model has it already");
    try {
      spec.effects.push_back(model::EffectSpecFromJson(name, "--add-effect"));
    } catch (const InputError& e) {
      throw UsageError(std::string("--add-effect: ") + e.what());
    }
  }
  return spec;
}

// The joint calibration again with the model to fit, when the parent's
// cameras were its and its samples.h5 holds the board frames: from the
// parent's cameras, so the new model's effects are fitted with the cameras
// rather than left in them. Rewrites calibration["cameras"]; nothing
// (nothing changed) otherwise or when it fails.
std::optional<JointCameras> RefitCamerasJointly(const RefitOptions& options, const ModelSpec& spec,
                                                const SessionManifest& manifest, const CachedSamples& cached,
                                                const fs::path& parent, nlohmann::json& calibration) {
  if (!calibration["cameras"].value("joint", nlohmann::json()).is_object() || cached.board_frames.empty() ||
      !manifest.rig)
    return std::nullopt;
  CameraCalibration start =
      CamerasFromJson(calibration["cameras"], (parent / "calibration.json").string() + ": cameras");
  AttachSessionPriors(manifest, start);
  const BoardGeometry board{manifest.rig->squares_x, manifest.rig->squares_y, manifest.rig->square_size_m};
  joint::JointOptions joint_options;
  joint_options.enabled = true;
  const ExtrinsicsOptions extrinsics;
  auto out = FitCamerasJointly({joint_options, extrinsics, board, start, spec, DepthReading(manifest.depth_units),
                                cached.board_frames, cached.samples, options.diagnosis.folds,
                                parent.filename().string() + "'s", " again"});
  if (out) calibration["cameras"] = CamerasJson(out->cameras);
  return out;
}

// The refit against its parent where no pose reached (pipeline/unseen_regions.h);
// nothing when either calibration cannot be applied (the plausibility gate
// and apply-calibration say why).
std::optional<UnseenChange> UnseenRegions(const fs::path& parent, const nlohmann::json& calibration,
                                          const ModelLab& lab) {
  try {
    return LargestUnseenChange(apply::LoadDepthCalibration(parent),
                               apply::DepthCalibrationFromJson(calibration, parent / "calibration.json"),
                               lab.diagnosis.coverage, DepthUncertainty(lab.Chosen(), lab.ChosenSamples()));
  } catch (const InputError& e) {
    spdlog::info("the refit is not compared with {} where no pose reached: {}", parent.filename().string(), e.what());
    return std::nullopt;
  }
}

// The unseen regions' line in the summary and report.json (a parent's, from
// an earlier refit, is replaced); returns the warnings the report carries.
std::vector<std::string> NoteUnseenRegions(const nlohmann::json& calibration, RefitOutcome& out,
                                           nlohmann::json& report) {
  std::vector<std::string> warnings = LoggedWarnings();
  report.erase("unseen_regions");
  const auto unseen = UnseenRegions(out.parent, calibration, out.lab);
  if (!unseen) return warnings;
  report["unseen_regions"] = ToJson(*unseen);
  out.costs += UnseenChangeLine(*unseen, out.parent.filename().string());
  if (unseen->BeyondSigma()) warnings.push_back(UnseenChangeWarning(*unseen, out.parent.filename().string()));
  return warnings;
}

}  // namespace

RefitOutcome RunRefit(const RefitOptions& options) {
  const StepClock clock;
  RefitOutcome out;
  out.parent = ParentVersionDir(options);
  ParentVersion parent_version = ReadParentVersion(out.parent);
  nlohmann::json& calibration = parent_version.calibration;
  nlohmann::json& report = parent_version.report;
  RequireThisSessionsRecordings(out.parent, calibration, options.session);
  // The reader's check (apply/plausibility.h): a refit would carry the
  // parent's cameras and depth scale on.
  if (const auto problems = apply::UnacceptedProblems(calibration); !problems.empty())
    throw InputError((out.parent / "calibration.json").string() + ": " + apply::kNotOfTheFamily +
                     ", so there is nothing to refit from: " + apply::JoinProblems(problems));
  // Read as apply-calibration reads it: a damaged parent is refused here,
  // naming the field, not met halfway through the refit (issue 47's probe).
  apply::LoadDepthCalibration(out.parent / "calibration.json");
  const bool accepted = options.accept_implausible ||
                        calibration.value("plausibility", nlohmann::json::object()).value("accepted", false);
  const ModelSpec spec = SpecToFit(options, out.parent, calibration);
  const std::string fingerprint =
      RunFingerprint({{"verb", "refit"},
                      {"parent", out.parent.filename().string()},
                      {"parent_calibration_sha256", Sha256File(out.parent / "calibration.json")},
                      {"session_json_sha256", Sha256File(fs::path(options.session) / kSessionFileName)},
                      {"model_spec", ToJson(spec)},
                      {"session_as_typed", options.session},
                      {"refit_tool", options.refit_tool},
                      {"judge_beyond_cameras", options.diagnosis.judge_beyond_cameras},
                      {"accept_implausible", accepted}});
  if (const auto same = options.new_version ? std::nullopt : VersionWithFingerprint(options.session, fingerprint)) {
    out.version = *same;
    out.unchanged = true;
    return out;
  }
  const StepClock reading_clock;
  const CachedSamples cached = ReadSamples(out.parent / "samples.h5");
  out.reading_seconds = reading_clock.Seconds();
  out.samples = cached.samples.size();
  std::optional<UndistortionGrid> grid;
  if (fs::exists(out.parent / "undistortion_grid.h5")) grid = ReadGrid(out.parent / "undistortion_grid.h5");
  const SessionManifest manifest = ReadSessionManifest(options.session);
  CheckModelUnits(spec, manifest.depth_units,
                  (options.model_file.empty() ? std::string("the starting version's model") : options.model_file) +
                      (options.add_effects.empty() ? "" : " with --add-effect") +
                      (options.base_form.empty() ? "" : " with --base-form"));
  const nlohmann::json parent_calibration = calibration;
  std::optional<JointCameras> joint = RefitCamerasJointly(options, spec, manifest, cached, out.parent, calibration);
  const std::vector<PairedSample>& samples = joint ? joint->samples : cached.samples;
  const DepthPerturbations& perturbations = joint ? joint->perturbations : cached.perturbations;
  out.lab = RunModelLab({spec, samples, grid, perturbations, manifest.depth_units, options.session, options.refit_tool,
                         options.diagnosis, joint ? joint->judge : HeldOutJudge{}});
  out.against_parent = AgainstParentLine(out.parent.filename().string(), parent_calibration, out.lab) +
                       PromiseLine(out.parent.filename().string(), report, options, out.lab);
  out.costs =
      RefitCosts(report, out.parent.filename().string(), out.lab,
                 CamerasFromJson(calibration["cameras"], (out.parent / "calibration.json").string() + ": cameras"));
  if (!joint && calibration["cameras"].value("joint", nlohmann::json()).is_object())
    out.held_joint_cameras = fmt::format(
        "the cameras are {}'s joint calibration, fitted with its model ({}) and held here, so what they took up "
        "stays in them; to fit them with this model run run-pipeline {} --model MODEL.json (this "
        "version's model_spec)",
        out.parent.filename().string(), calibration["model"].value("name", std::string("?")), options.session);
  calibration["created_utc"] = UtcNowIso8601();
  calibration["tool_version"] = kToolVersion;
  calibration["parent_version"] = out.parent.filename().string();
  calibration["run_fingerprint"] = fingerprint;
  SetModelJson(spec, out.lab, calibration, report);
  MarkPlausibility(calibration, accepted);
  out.plausibility = calibration["plausibility"];
  if (!out.held_joint_cameras.empty()) spdlog::warn("{}", out.held_joint_cameras);
  AddAssessment(report, calibration, NoteUnseenRegions(calibration, out, report));
  out.assessment_line = AssessmentLine(report);
  report["step_seconds"]["reading_samples"] = out.reading_seconds;
  report["step_seconds"]["total"] = clock.Seconds();  // up to writing the version
  out.version = WriteCalibrationVersion(
      options.session, {calibration, report, samples, perturbations, grid ? &*grid : nullptr, PlotDataJson(out.lab),
                        cached.board_frames.empty() ? nullptr : &cached.board_frames});
  out.seconds = clock.Seconds();
  return out;
}

}  // namespace speckle
