// record-session's SOURCE kinds: the one table (kSources, at the end) and
// each kind's planner, which turns the command line into the session's plan.
//
// To add an importer (a new SOURCE kind):
//  1. Write its reader in recorder/sources/NAME_source.{h,cc}; tum_source is
//     the one to copy (a folder, one recording, colour and depth paired by
//     stamp). PlanNAMEImport(path, options, notes) reads and checks every
//     file before a frame is written and throws InputError naming the file.
//     List the .cc in recorder/CMakeLists.txt (speckle_recorder).
//  2. Below, write PlanNAME(flags, path, plan): the flags to its options,
//     then the manifest's driver (and depth units when not raw 11-bit) and
//     its recording(s) into plan.
//  3. Add its line to kSources: name, "DIR" or "FILE" (nullptr if it takes
//     no path), a one-line description and PlanNAME (a kind that reads an
//     existing layout may reuse that kind's planner). SOURCE's check and
//     help and --help's list of kinds come from the table, in its order.
//     tests/bad_input_test.cc pins that list (Usage.UnknownSourceIsAUsageError,
//     Usage.HelpListsEverySourceKind): add the kind there too.
//  4. Only if it needs a flag of its own: a field in SourceFlags
//     (source_kind.h) and its option in record_session_main.cc
//     (AddImportOptions), its help starting with the kinds it applies to.
//  5. Test it through the tool: tests/import_test.cc imports folders from
//     ../shared/data; tests/ros_import_test.py writes TUM folders and bags
//     from simulated sessions. Then `clang-format -i` the files you touched
//     and `cd build && ctest -L fast` (it checks format and lengths too).
#include <nlohmann/json.hpp>

#include "apps/sources/source_kind.h"
#include "recorder/sources/fakenect_source.h"
#include "recorder/sources/frames_dir_source.h"
#include "recorder/sources/freenect_source.h"
#include "recorder/sources/rosbag_source.h"
#include "recorder/sources/sim_source.h"
#include "recorder/sources/tum_source.h"
#include "schemas/errors.h"
#include "schemas/json_fields.h"
#include "simulator/scenario_usability.h"

namespace speckle {
namespace {

// The simulator plans every recording its scenario makes; --purpose keeps one.
void KeepPurpose(const std::string& purpose, SessionPlan& plan) {
  if (purpose.empty()) return;
  const RecordingPurpose wanted = PurposeFromString(purpose);
  std::erase_if(plan.recordings, [&](const PlannedRecording& r) { return r.header.purpose != wanted; });
  if (plan.recordings.empty()) throw InputError("--purpose " + purpose + ": the scenario makes no such recording");
}

// The simulator describes the whole session; only the session's own stamps
// (a new one's, or those of the session --add-to names) stay.
void PlanSim(const SourceFlags& flags, const std::string&, SessionPlan& plan) {
  nlohmann::json json = flags.scenario.empty() ? nlohmann::json::object() : ReadJsonFile(flags.scenario);
  // Before parsing: a randomized scenario draws its sensor and room from the seed.
  if (flags.seed) json["seed"] = *flags.seed;
  const std::string origin = flags.scenario.empty() ? "default scenario" : flags.scenario;
  const sim::Scenario scenario = sim::ScenarioFromJson(json, origin);
  sim::CheckUsable(scenario, origin);
  const SessionManifest base = std::move(plan.manifest);
  plan = PlanSimulatedSession(scenario, {flags.realtime});
  plan.manifest.created_utc = base.created_utc;
  plan.manifest.tool_version = base.tool_version;
  KeepPurpose(flags.purpose, plan);
  // IR images alone calibrate no depth: asked for by --purpose (to add to a
  // session), not made as a session that run-pipeline can only refuse.
  if (flags.purpose.empty() && std::none_of(plan.recordings.begin(), plan.recordings.end(), [](const auto& r) {
        return r.header.purpose == RecordingPurpose::kDepthboard || r.header.purpose == RecordingPurpose::kPlanar;
      }))
    throw InputError(origin +
                     ": records nothing to calibrate depth from: depthboard.poses and planar.snapshots are both 0 "
                     "(an IR chessboard recording alone is made with --purpose ir_chessboard, to add to a session)");
}

// Written in place, so a kill keeps what was flushed.
void PlanFreenect(const SourceFlags& flags, const std::string&, SessionPlan& plan) {
  FreenectCaptureOptions options;
  options.device_index = flags.device;
  options.duration_s = flags.duration_s;
  if (!flags.purpose.empty()) options.purpose = PurposeFromString(flags.purpose);
  plan.streaming = true;
  plan.manifest.driver = "libfreenect";
  plan.recordings.push_back(PlanFreenectCapture(options, &plan.notes));
}

void PlanFakenect(const SourceFlags& flags, const std::string& path, SessionPlan& plan) {
  FakenectImportOptions options;
  if (!flags.purpose.empty()) options.purpose = PurposeFromString(flags.purpose);
  options.allow_unpaired = flags.allow_unpaired;
  options.max_pair_gap_s = flags.max_pair_gap_ms / 1000;
  plan.manifest.driver = "libfreenect";
  plan.recordings.push_back(PlanFakenectImport(path, options, &plan.notes));
}

// Depth-only frames go to their own recording unless --depth-only keep, or
// unless their purpose is the paired frames' own.
void PlanFrames(const SourceFlags& flags, const std::string& path, SessionPlan& plan) {
  FramesImportOptions options;
  if (!flags.purpose.empty()) options.paired_purpose = PurposeFromString(flags.purpose);
  options.depth_only_purpose =
      flags.depth_only == "keep" ? std::nullopt : std::optional(PurposeFromString(flags.depth_only));
  if (options.depth_only_purpose == options.paired_purpose) options.depth_only_purpose.reset();
  plan.manifest.driver = "libfreenect";
  plan.recordings = PlanFramesImport(path, options, &plan.notes);
}

// TUM's depth is millimetres (OpenNI's), never raw 11-bit values.
void PlanTum(const SourceFlags& flags, const std::string& path, SessionPlan& plan) {
  TumImportOptions options;
  if (!flags.purpose.empty()) options.purpose = PurposeFromString(flags.purpose);
  options.max_pair_gap_s = flags.max_pair_gap_ms / 1000;
  plan.manifest.driver = "openni";
  plan.manifest.depth_units = DepthUnits::kMillimetre;
  plan.recordings.push_back(PlanTumImport(path, options, &plan.notes));
}

// A bag's depth units are given or detected, and its driver follows from
// them; its camera_info, when kept, is the session's known intrinsics.
void PlanRosbag(const SourceFlags& flags, const std::string& path, SessionPlan& plan) {
  RosbagImportOptions options = flags.rosbag;
  if (!flags.purpose.empty()) options.purpose = PurposeFromString(flags.purpose);
  options.allow_unpaired = flags.allow_unpaired;
  options.max_pair_gap_s = flags.max_pair_gap_ms / 1000;
  if (flags.depth_units != "auto") options.depth_units = DepthUnitsFromString(flags.depth_units);
  RosbagImport bag = PlanRosbagImport(path, options, &plan.notes);
  if (bag.recording.header.depth_size) plan.manifest.depth_units = bag.depth_units;
  plan.manifest.driver = bag.depth_units == DepthUnits::kMillimetre ? "openni" : "libfreenect";
  if (bag.colour_intrinsics) plan.manifest.colour_intrinsics = bag.colour_intrinsics;
  if (bag.depth_intrinsics) plan.manifest.depth_intrinsics = bag.depth_intrinsics;
  plan.recordings.push_back(std::move(bag.recording));
}

// One line per kind; help and the SOURCE message list them in this order.
constexpr SourceKind kSources[] = {
    {"sim", nullptr, "built-in simulator (--scenario, --seed)", PlanSim},
    {"freenect", nullptr, "live Kinect (libfreenect)", PlanFreenect},
    {"fakenect", "DIR", "libfreenect `record` dump", PlanFakenect},
    {"frames", "DIR", "NNNN-c1.jpg / NNNN-d.pgm folder (Herrera's and Xiang's toolboxes)", PlanFrames},
    {"tum", "DIR", "TUM RGB-D layout: rgb.txt, depth.txt, millimetre depth", PlanTum},
    {"rosbag", "FILE", "ROS 1 bag of sensor_msgs/Image", PlanRosbag},
};

}  // namespace

std::span<const SourceKind> SourceKinds() { return kSources; }

}  // namespace speckle
