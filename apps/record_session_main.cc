// record-session SOURCE --out SESSION_DIR: records or imports a session.
// record-session SOURCE --add-to SESSION_DIR: adds to an existing one.
// SOURCE is sim, fakenect:DIR, frames:DIR, tum:DIR, rosbag:FILE or freenect; `freenect --purpose
// ir_chessboard` records the IR camera for the thesis's IR step.
#include <spdlog/spdlog.h>
#include <iostream>
#include "apps/cli_main.h"

#include "recorder/session_append.h"
#include "recorder/session_recorder.h"
#include "recorder/sources/fakenect_source.h"
#include "recorder/sources/frames_dir_source.h"
#include "recorder/sources/freenect_source.h"
#include "recorder/sources/rosbag_source.h"
#include "recorder/sources/sim_source.h"
#include "recorder/sources/tum_source.h"
#include "schemas/errors.h"
#include "schemas/json_fields.h"
#include "schemas/staging.h"
#include "simulator/sim_effect.h"

namespace {

using namespace speckle;

struct Flags {
  std::string source;
  std::string out;
  std::string add_to;  // an existing session to add the recording(s) to
  std::string scenario;
  std::optional<std::uint64_t> seed;
  bool realtime = false;
  std::string codec = "szip";
  int flush_interval_ms = 500;
  std::string description_file;
  std::string squares;  // "9x7"
  double square_size_m = 0;
  std::string outline = "unknown";
  std::string label, serial, optics, notes;
  std::string purpose;
  bool allow_unpaired = false;
  double max_pair_gap_ms = 20;
  std::string depth_only = "planar";
  RosbagImportOptions rosbag;  // topics, --depth-units, --use-camera-info
  std::string depth_units = "auto";
  double duration_s = 0;
  int device = 0;
};

// Sensor, rig and optics from --describe FILE (a session.json or a subset of
// it), then from flags, which win.
void DescribeSession(const Flags& flags, SessionManifest& m) {
  if (!flags.description_file.empty()) {
    const nlohmann::json json = ReadJsonFile(flags.description_file);
    JsonFields f(json, flags.description_file);
    for (const char* ignored :
         {"schema", "schema_version", "recordings", "created_utc", "tool_version", "depth_units", "driver"}) {
      f.OptionalValue(ignored);
    }
    if (const auto* sensor = f.OptionalValue("sensor")) {
      JsonFields s(*sensor, f.Path("sensor"));
      m.sensor.model = s.Optional<std::string>("model", m.sensor.model);
      m.sensor.label = s.Optional<std::string>("label", m.sensor.label);
      m.sensor.serial = s.Optional<std::string>("serial", m.sensor.serial);
      s.RejectUnknownKeys();
    }
    if (const auto* rig = f.OptionalValue("rig")) m.rig = RigFromJson(*rig, f.Path("rig"));
    if (const auto* cameras = f.OptionalValue("cameras")) {
      JsonFields c(*cameras, f.Path("cameras"));
      if (const auto* colour = c.OptionalValue("colour"))
        m.colour_intrinsics = IntrinsicsFromJson(*colour, c.Path("colour"));
      if (const auto* depth = c.OptionalValue("depth"))
        m.depth_intrinsics = IntrinsicsFromJson(*depth, c.Path("depth"));
      c.RejectUnknownKeys();
    }
    m.optics = f.Optional<std::string>("optics", m.optics);
    m.notes = f.Optional<std::string>("notes", m.notes);
    f.RejectUnknownKeys();
  }
  if (!flags.squares.empty()) {
    int x = 0, y = 0;
    char sep = 0;
    std::istringstream in(flags.squares);
    if (!(in >> x >> sep >> y) || sep != 'x' || x < 2 || y < 2) {
      throw InputError("--squares: expected COLSxROWS of chessboard squares, e.g. 9x7, found \"" + flags.squares +
                       "\"");
    }
    if (flags.square_size_m <= 0) throw InputError("--squares needs --square-size (metres)");
    m.rig = RigInfo{x, y, flags.square_size_m, BoardOutlineFromString(flags.outline), ""};
  }
  if (!flags.label.empty()) m.sensor.label = flags.label;
  if (!flags.serial.empty()) m.sensor.serial = flags.serial;
  if (!flags.optics.empty()) m.optics = flags.optics;
  if (!flags.notes.empty()) m.notes = flags.notes;
}

// The simulator plans every recording its scenario makes; --purpose keeps one.
void KeepPurpose(const std::string& purpose, SessionPlan& plan) {
  if (purpose.empty()) return;
  const RecordingPurpose wanted = PurposeFromString(purpose);
  std::erase_if(plan.recordings, [&](const PlannedRecording& r) { return r.header.purpose != wanted; });
  if (plan.recordings.empty()) throw InputError("--purpose " + purpose + ": the scenario makes no such recording");
}

// `base` is the manifest the source's and the flags' values are laid over:
// defaults for a new session, the existing manifest for --add-to.
SessionPlan Plan(const Flags& flags, const SessionManifest& base) {
  const auto colon = flags.source.find(':');
  const std::string kind = flags.source.substr(0, colon);
  const std::string path = colon == std::string::npos ? "" : flags.source.substr(colon + 1);
  const bool needs_path = kind == "fakenect" || kind == "frames" || kind == "tum" || kind == "rosbag";
  if (needs_path == path.empty() || (kind != "sim" && kind != "freenect" && !needs_path)) {
    throw CLI::ValidationError(
        "SOURCE",
        "expected sim, freenect, fakenect:DIR, frames:DIR, tum:DIR or rosbag:FILE, found \"" + flags.source + "\"");
  }
  if (flags.seed && kind != "sim") throw CLI::ValidationError("--seed", "only the simulator (SOURCE sim) has a seed");
  SessionPlan plan;
  plan.manifest = base;
  if (kind == "sim") {
    sim::Scenario scenario;
    nlohmann::json json = flags.scenario.empty() ? nlohmann::json::object() : ReadJsonFile(flags.scenario);
    // Before parsing: a randomized scenario draws its sensor and room from the seed.
    if (flags.seed) json["seed"] = *flags.seed;
    scenario = sim::ScenarioFromJson(json, flags.scenario.empty() ? "default scenario" : flags.scenario);
    plan = PlanSimulatedSession(scenario, {flags.realtime});
    plan.manifest.created_utc = base.created_utc;
    plan.manifest.tool_version = base.tool_version;
    KeepPurpose(flags.purpose, plan);
  } else if (kind == "fakenect") {
    FakenectImportOptions options;
    if (!flags.purpose.empty()) options.purpose = PurposeFromString(flags.purpose);
    options.allow_unpaired = flags.allow_unpaired;
    options.max_pair_gap_s = flags.max_pair_gap_ms / 1000;
    plan.manifest.driver = "libfreenect";
    plan.recordings.push_back(PlanFakenectImport(path, options, &plan.notes));
  } else if (kind == "frames") {
    FramesImportOptions options;
    if (!flags.purpose.empty()) options.paired_purpose = PurposeFromString(flags.purpose);
    options.depth_only_purpose =
        flags.depth_only == "keep" ? std::nullopt : std::optional(PurposeFromString(flags.depth_only));
    if (options.depth_only_purpose == options.paired_purpose) options.depth_only_purpose.reset();
    plan.manifest.driver = "libfreenect";
    plan.recordings = PlanFramesImport(path, options, &plan.notes);
  } else if (kind == "tum") {
    TumImportOptions options;
    if (!flags.purpose.empty()) options.purpose = PurposeFromString(flags.purpose);
    options.max_pair_gap_s = flags.max_pair_gap_ms / 1000;
    plan.manifest.driver = "openni";
    plan.manifest.depth_units = DepthUnits::kMillimetre;
    plan.recordings.push_back(PlanTumImport(path, options, &plan.notes));
  } else if (kind == "rosbag") {
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
  } else {
    FreenectCaptureOptions options;
    options.device_index = flags.device;
    options.duration_s = flags.duration_s;
    if (!flags.purpose.empty()) options.purpose = PurposeFromString(flags.purpose);
    plan.streaming = true;
    plan.manifest.driver = "libfreenect";
    plan.recordings.push_back(PlanFreenectCapture(options, &plan.notes));
  }
  DescribeSession(flags, plan.manifest);
  return plan;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Record a depth-camera session (HDF5 recordings + session.json).\n"
      "SOURCE: sim (built-in simulator), fakenect:DIR (libfreenect `record` dump),\n"
      "        frames:DIR (NNNN-c1.jpg / NNNN-d.pgm folder), tum:DIR (TUM RGB-D layout: rgb.txt, depth.txt,\n"
      "        millimetre depth), rosbag:FILE (ROS 1 bag of sensor_msgs/Image), freenect (live Kinect)"};
  Flags flags;
  app.add_option("SOURCE", flags.source, "sim | fakenect:DIR | frames:DIR | tum:DIR | rosbag:FILE | freenect")
      ->required();
  auto* out = app.add_option("-o,--out", flags.out, "new session directory (must not exist)");
  app.add_option("--add-to", flags.add_to,
                 "existing session to add the recording(s) to, all or nothing; refused when sensor, driver, depth "
                 "units, image sizes or purpose clash")
      ->excludes(out);
  auto* sim_group = app.add_option_group("simulator");
  sim_group->add_option("--scenario", flags.scenario, "scenario JSON (defaults: a stock-optics session)");
  sim_group->add_option(
      "--seed", flags.seed,
      "override the scenario's seed (one scenario file, many drawn sessions when it has \"randomize\")");
  sim_group->add_flag("--realtime", flags.realtime, "emit frames at the sensor's frame rate");
  app.add_flag_callback(
      "--list-effects",
      [] {
        for (const auto& e : sim::SimEffectCatalogue()) std::cout << e.name << "\t" << e.doc << "\n";
        throw CLI::Success();
      },
      "list the simulator's physical effects and exit");
  auto* describe = app.add_option_group("session description");
  describe->add_option("--describe", flags.description_file,
                       "session.json (or a subset) giving sensor, rig, optics, cameras (known intrinsics), notes");
  describe->add_option("--squares", flags.squares, "chessboard squares COLSxROWS, e.g. 9x7");
  describe->add_option("--square-size", flags.square_size_m, "square size in metres");
  describe->add_option("--outline", flags.outline,
                       "board outline vs depth step: chessboard_edge | larger_board | unknown");
  describe->add_option("--label", flags.label, "your name for this sensor");
  describe->add_option("--serial", flags.serial, "sensor serial");
  describe->add_option("--optics", flags.optics, "optics label: stock, wide_angle, ...");
  describe->add_option("--notes", flags.notes, "free notes");
  auto* import = app.add_option_group("import");
  import->add_option("--purpose", flags.purpose,
                     "recording purpose: depthboard | planar | ir_chessboard | free (sim: keep only that recording;\n"
                     "freenect: ir_chessboard records IR frames of the board, projector covered)");
  import->add_flag("--allow-unpaired", flags.allow_unpaired,
                   "fakenect, rosbag: keep frames with no partner as single-stream frames");
  import->add_option("--max-pair-gap-ms", flags.max_pair_gap_ms,
                     "fakenect, tum, rosbag: largest colour/depth time gap of a pair");
  import->add_option("--depth-only", flags.depth_only,
                     "frames: purpose for depth-only frames (planar | depthboard | keep)");
  auto* ros = app.add_option_group("rosbag");
  ros->add_option("--depth-topic", flags.rosbag.depth_topic, "rosbag: depth images (16UC1 or 32FC1)")
      ->capture_default_str();
  ros->add_option("--colour-topic", flags.rosbag.colour_topic, "rosbag: colour images (rgb8, bgr8, bayer_grbg8)")
      ->capture_default_str();
  ros->add_option("--ir-topic", flags.rosbag.ir_topic, "rosbag: IR images (mono16), read for --purpose ir_chessboard")
      ->capture_default_str();
  ros->add_option(
         "--depth-units", flags.depth_units,
         "rosbag: what 16UC1 depth holds: raw_11bit | millimetre | auto (2047 and no 0: raw; else millimetres)")
      ->check(CLI::IsMember({"auto", "raw_11bit", "millimetre"}));
  ros->add_flag("--use-camera-info", flags.rosbag.use_camera_info,
                "rosbag: keep the camera_info beside each image topic as the session's known intrinsics");
  auto* live = app.add_option_group("live");
  live->add_option("--duration", flags.duration_s, "freenect: seconds to record (0 = until Ctrl-C)");
  live->add_option("--device", flags.device, "freenect: device index");
  auto* writer = app.add_option_group("writer");
  writer->add_option(
      "--codec", flags.codec,
      "chunk compression: szip (default, small) | lz4 (fastest; HDF5 filter plugin) | deflate (portable) | none");
  writer->add_option("--flush-interval-ms", flags.flush_interval_ms, "longest time between flushes to disk")
      ->check(CLI::Range(10, 1000));
  return RunCli("record-session", app, argc, argv, [&] {
    if (flags.out.empty() == flags.add_to.empty()) {
      throw CLI::ValidationError("--out/--add-to",
                                 "give a new session directory with --out, or an existing one with --add-to");
    }
    RequireExisting(flags.scenario, "--scenario", false);
    RequireExisting(flags.description_file, "--describe", false);
    const bool adding = !flags.add_to.empty();
    SessionPlan plan = Plan(flags, adding ? ReadSessionToAppendTo(flags.add_to) : SessionManifest{});
    for (const auto& note : plan.notes) spdlog::info("{}", note);
    SessionRecorderOptions options;
    options.writer.codec = CodecFromString(flags.codec);
    options.writer.flush_interval = std::chrono::milliseconds(flags.flush_interval_ms);
    const SessionRecordSummary summary =
        adding ? AppendToSession(std::move(plan), flags.add_to, options)
               : RecordSession(std::move(plan), NormalizeOutPath(flags.out, "--out"), options);
    for (const auto& r : summary.recordings) spdlog::info("{}: {} frames ({})", r.file, r.frames, ToString(r.purpose));
    if (summary.stopped_early) spdlog::info("stopped on request; what was recorded is kept");
    std::cout << summary.session_dir.string() << "\n";
    return kExitOk;
  });
}
