#pragma once
// The refit use case: a calibration version's cached samples fitted again
// with another model (the version's own spec, a model file, or it with
// catalogue effects added), diagnosed, and written as a new version whose
// parent is the one it started from. No frame is read or detected again.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lab/model_lab.h"

namespace speckle {

struct RefitOptions {
  std::string session;                   // as the user typed it: the verdict's commands repeat it
  std::string from;                      // "v0002"; empty: the newest version
  std::string model_file;                // a whole model spec; empty: the parent's model_spec
  std::vector<std::string> add_effects;  // catalogue effects added to that model
  std::string base_form;                 // "tangent": that model's base form replaced; empty: kept
  std::string refit_tool = "refit";      // how the verdict's commands name this tool
  bool accept_implausible = false;       // see pipeline/plausibility_gate.h; a parent's acceptance carries on
  bool new_version = false;              // written even when a version has this refit's fingerprint
  DiagnosisOptions diagnosis;
};

struct RefitOutcome {
  std::filesystem::path version;  // the version written, or the one with this refit's fingerprint
  bool unchanged = false;  // true: nothing written, `version` was made by the same refit (pipeline/run_fingerprint.h)
  std::filesystem::path parent;  // the version it started from
  std::size_t samples = 0;
  ModelLab lab;
  // "against v0001 (...): held-out a -> b raw (+x %)", or empty when the
  // parent has no held-out error to compare with.
  std::string against_parent;
  // Said when the parent's cameras came from the joint calibration: a
  // refit holds them (it does not re-run the joint fit yet), so what they
  // took up with the parent's model stays in them. Empty otherwise.
  std::string held_joint_cameras;  // logged before the version is written
  std::string assessment_line;     // "result       ..." (pipeline/assessment.h)
  std::string costs;               // pipeline/refit_costs.h: the depth sigma against the parent's, camera warnings
  nlohmann::json plausibility;     // the new version's calibration.json "plausibility"
  double reading_seconds = 0;
  double seconds = 0;  // up to writing the version
};

// Throws InputError (naming the file or flag) for a missing version, a model
// the session's units cannot use, or an effect the model has already.
RefitOutcome RunRefit(const RefitOptions& options);

}  // namespace speckle
