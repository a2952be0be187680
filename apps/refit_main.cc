// refit SESSION_DIR [--from vNNNN] [--model MODEL.json] [--add-effect NAME]...
// Refits a calibration's cached samples with another model, without
// detecting anything again, and writes a new version whose parent is the
// version it started from.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <iostream>

#include "apps/cli_main.h"
#include "apps/model_summary.h"
#include "pipeline/logged_warnings.h"
#include "pipeline/plausibility_gate.h"
#include "pipeline/refit_run.h"
#include "pipeline/run_fingerprint.h"
#include "pipeline/step_seconds.h"

int main(int argc, char** argv) {
  using namespace speckle;
  CLI::App app{
      "Refit a calibration's cached samples with another model (seconds, no detection) and diagnose it.\n"
      "Writes a new version SESSION_DIR/calibrations/vNNNN/ and prints a summary with a verdict."};
  RefitOptions options;
  app.add_option("SESSION_DIR", options.session, "session directory with at least one calibration")->required();
  app.add_option("--from", options.from, "version to start from, e.g. v0002 (default: the newest)");
  app.add_option("--model", options.model_file,
                 "model spec JSON, the whole model (default: the starting version's spec, its model_spec in "
                 "calibration.json)");
  app.add_option("--add-effect", options.add_effects, "add a catalogue effect to the model (repeatable)");
  app.add_option("--base-form", options.base_form,
                 "replace the model's base form (reciprocal, disparity, tangent, ...), its effects kept");
  app.add_flag("--judge-beyond-cameras", options.diagnosis.judge_beyond_cameras,
               "judge the model beyond the cameras: candidates fitted with the cameras free within their uncertainty, "
               "complete against the floor without the cameras' part (on trial: issue 46)");
  app.add_flag("--accept-implausible", options.accept_implausible,
               "keep a result no Kinect v1 / PrimeSense sensor gives as a calibration (see run-pipeline --help)");
  app.add_flag("--new-version", options.new_version,
               "write a new version even when one was made by this same refit (same parent, model, options and build; "
               "otherwise that version is named and nothing is written)");
  return RunCli("refit", app, argc, argv, [&] {
    KeepLoggedWarnings();
    RequireExisting(options.session, "SESSION_DIR", true);
    RequireExisting(options.model_file, "--model", false);
    options.refit_tool = ToolBeside(argv[0], "refit");
    const RefitOutcome refit = RunRefit(options);
    if (refit.unchanged) {
      SayUnchanged(refit.version);
      return kExitOk;
    }
    std::cout << fmt::format("calibration  {} (refit of {}, {} cached samples)\n", refit.version.string(),
                             refit.parent.filename().string(), refit.samples)
              << refit.against_parent << ModelSummary(refit.lab) << refit.costs << refit.assessment_line
              << StepSecondsLine(refit.lab, refit.seconds, std::nullopt, std::nullopt, std::nullopt,
                                 refit.reading_seconds);
    EndIfImplausible(refit.version, refit.plausibility);
    return kExitOk;
  });
}
