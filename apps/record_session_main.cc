// record-session SOURCE --out SESSION_DIR: records or imports a session.
// record-session SOURCE --add-to SESSION_DIR: adds to an existing one.
// SOURCE is one of the kinds in apps/sources/source_table.cc (`--help` lists
// them); `freenect --purpose ir_chessboard` records the IR camera for the
// thesis's IR step.
#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <cmath>
#include <iostream>
#include <limits>
#include "apps/cli_main.h"
#include "apps/given_camera.h"

#include "apps/sources/source_kind.h"
#include "recorder/session_append.h"
#include "recorder/session_recorder.h"
#include "schemas/artifact_schema.h"
#include "schemas/errors.h"
#include "schemas/json_fields.h"
#include "schemas/staging.h"
#include "simulator/sim_effect.h"

namespace {

using namespace speckle;

// What the sources' planners read is in SourceFlags; the rest is the
// session's description and the writer's.
struct Flags : SourceFlags {
  std::string source;
  std::string out;
  std::string add_to;  // an existing session to add the recording(s) to
  std::string codec = "szip";
  int flush_interval_ms = 500;
  std::string description_file;
  std::string squares;                                              // "9x7"
  double square_size_m = std::numeric_limits<double>::quiet_NaN();  // NaN: not given
  std::string outline = "unknown";
  std::string label, serial, optics, notes;
  GivenCameraFlags colour_camera, depth_camera;
};

// The square size is checked before anything is recorded: a size in
// millimetres typed as metres made a 170 MB session that only run-pipeline
// refused, and 0 or a negative size was reported as missing.
void CheckSquareSize(double square_size_m) {
  if (std::isnan(square_size_m)) throw UsageError("--squares needs --square-size (the side of one square, in metres)");
  if (!(square_size_m > 0))
    throw UsageError(
        fmt::format("--square-size {}: a square's side must be positive (metres, e.g. 0.04)", square_size_m));
  if (square_size_m > kMaxSquareSizeM)
    throw UsageError(
        fmt::format("--square-size {}: the size is in metres ({} m is no chessboard square); for {} mm "
                    "give --square-size {}",
                    square_size_m, square_size_m, square_size_m, square_size_m / 1000));
  if (square_size_m < kMinSquareSizeM)
    throw UsageError(
        fmt::format("--square-size {}: a square under 1 mm is not a calibration board (the size is in "
                    "metres, e.g. 0.04 for 40 mm)",
                    square_size_m));
}

// Sensor, rig and optics from --describe FILE (a session.json or a subset of
// it), then from flags, which win.
void DescribeSession(const Flags& flags, SessionManifest& m) {
  if (!flags.description_file.empty()) {
    // A camera file typed here reads as broken JSON; say where it goes.
    const std::string extension = std::filesystem::path(flags.description_file).extension().string();
    if (extension == ".yaml" || extension == ".yml" || extension == ".xml" || extension == ".cameramodel")
      throw InputError(
          fmt::format("--describe {}: takes a session.json subset; a camera file goes in with "
                      "--colour-camera {} (or --depth-camera), with --colour-camera-sigma",
                      flags.description_file, flags.description_file));
    const nlohmann::json json = ReadJsonFile(flags.description_file);
    JsonFields f(json, flags.description_file);
    for (const char* ignored : {"schema", "recordings", "created_utc", "tool_version", "depth_units", "driver"}) {
      f.OptionalValue(ignored);
    }
    // A session.json of a newer tool may mean its keys otherwise: refused as
    // every versioned input is (issue 47's probe: relabelled 2 silently).
    if (f.Has("schema_version"))
      RequireSchemaVersion(flags.description_file, "speckle.session", f.Required<long long>("schema_version"),
                           kSessionSchemaVersion, kOldestSessionSchemaVersion);
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
    // The reader's bounds (schemas/session_manifest.h): the writer wrote a session.json its own reader refused.
    // Nothing may follow ROWS: "9x7x2" was taken as 9x7.
    if (!(in >> x >> sep >> y) || sep != 'x' || !(in >> std::ws).eof() || x < kMinSquaresPerSide ||
        y < kMinSquaresPerSide || x > kMaxSquaresPerSide || y > kMaxSquaresPerSide) {
      throw UsageError("--squares: expected COLSxROWS of chessboard squares, each " +
                       std::to_string(kMinSquaresPerSide) + " to " + std::to_string(kMaxSquaresPerSide) +
                       ", e.g. 9x7, found \"" + flags.squares + "\"");
    }
    CheckSquareSize(flags.square_size_m);
    const RigInfo given{x, y, flags.square_size_m, BoardOutlineFromString(flags.outline), ""};
    // The simulator draws its scenario's board: a flag describing another
    // wrote a session.json about a board that is not in its frames.
    if (flags.source == "sim" && m.rig) {
      if (m.rig->squares_x != x || m.rig->squares_y != y || std::abs(m.rig->square_size_m - given.square_size_m) > 1e-9)
        throw InputError(
            fmt::format("--squares {} --square-size {}: the simulator draws its scenario's board, {}x{} "
                        "squares of {} m; change the board in the scenario (rig), not here",
                        flags.squares, flags.square_size_m, m.rig->squares_x, m.rig->squares_y, m.rig->square_size_m));
    } else {
      m.rig = given;
    }
  } else if (!std::isnan(flags.square_size_m)) {
    throw UsageError(
        fmt::format("--square-size {} is the size of the board's squares, and needs --squares "
                    "(COLSxROWS, e.g. 9x7) to describe the board",
                    flags.square_size_m));
  }
  if (!flags.label.empty()) m.sensor.label = flags.label;
  if (!flags.serial.empty()) m.sensor.serial = flags.serial;
  if (!flags.optics.empty()) m.optics = flags.optics;
  if (!flags.notes.empty()) m.notes = flags.notes;
}

// SOURCE and where the session goes; the order of --help's groups follows.
void AddSessionOptions(CLI::App& app, Flags& flags) {
  app.add_option("SOURCE", flags.source, SourceChoices())->required();
  auto* out = app.add_option("-o,--out", flags.out, "new session directory (must not exist)");
  app.add_option("--add-to", flags.add_to,
                 "existing session to add the recording(s) to, all or nothing; refused when sensor, driver, depth "
                 "units, image sizes or purpose clash")
      ->excludes(out);
}

void AddSimulatorOptions(CLI::App& app, Flags& flags) {
  auto* sim_group = app.add_option_group("simulator");
  sim_group->add_option("--scenario", flags.scenario, "scenario JSON (defaults: a stock-optics session)");
  sim_group
      ->add_option("--seed", flags.seed,
                   "override the scenario's seed (one scenario file, many drawn sessions when it has \"randomize\")")
      // CLI11 wraps -1 round to 18446744073709551615 otherwise (and its
      // NonNegativeNumber names the largest double in 309 digits).
      ->check(CLI::Validator(
          [](std::string& text) { return text.starts_with('-') ? std::string("a seed is 0 or more") : std::string(); },
          "SEED >= 0"));
  sim_group->add_flag("--realtime", flags.realtime, "emit frames at the sensor's frame rate");
  app.add_flag_callback(
      "--list-effects",
      [] {
        for (const auto& e : sim::SimEffectCatalogue()) std::cout << e.name << "\t" << e.doc << "\n";
        throw CLI::Success();
      },
      "list the simulator's physical effects and exit");
}

void AddDescriptionOptions(CLI::App& app, Flags& flags) {
  auto* describe = app.add_option_group("session description");
  describe->add_option("--describe", flags.description_file,
                       "session.json (or a subset) giving sensor, rig, optics, cameras (known intrinsics), notes");
  describe->add_option("--squares", flags.squares, "chessboard squares COLSxROWS, e.g. 9x7");
  describe->add_option("--square-size", flags.square_size_m, "square size in metres");
  describe
      ->add_option("--outline", flags.outline, "board outline vs depth step: chessboard_edge | larger_board | unknown")
      ->check(CLI::IsMember({"chessboard_edge", "larger_board", "unknown"}));
  describe->add_option("--label", flags.label, "your name for this sensor");
  describe->add_option("--serial", flags.serial, "sensor serial");
  describe->add_option("--optics", flags.optics, "optics label: stock, wide_angle, ...");
  describe->add_option("--notes", flags.notes, "free notes");
  for (auto [camera, given] : {std::pair{"colour", &flags.colour_camera}, std::pair{"depth", &flags.depth_camera}}) {
    const std::string flag = std::string("--") + camera + "-camera";
    describe->add_option(flag, given->file,
                         std::string("a calibrated ") + camera +
                             " camera: ROS camera_info YAML (ost.yaml), OpenCV FileStorage YAML/XML, mrcal "
                             ".cameramodel, Kalibr camchain.yaml (FILE#cam0); a prior with its sigmas");
    describe->add_option(flag + "-sigma", given->sigma,
                         "its standard deviations fx,fy,cx,cy (px)[,k1,k2,p1,p2,k3] when the file has none");
    describe->add_flag(flag + "-exact", given->exact, "take it as exact instead (no prior)");
  }
}

// The cameras the user gave as files, over --describe's; either must be
// for the recordings' image size (a camera of another size was written
// into session.json, and only apply-calibration refused the result).
void GiveCameras(const Flags& flags, SessionPlan& plan) {
  if (auto colour = GivenCamera(flags.colour_camera, "colour")) plan.manifest.colour_intrinsics = *colour;
  if (auto depth = GivenCamera(flags.depth_camera, "depth")) plan.manifest.depth_intrinsics = *depth;
  // The message names where the camera came from: the file flag, else --describe.
  const auto given_by = [](const GivenCameraFlags& given, const std::string& camera) {
    return given.file.empty() ? "--describe's cameras." + camera : "--" + camera + "-camera " + given.file;
  };
  if (plan.manifest.colour_intrinsics)
    CheckCameraFitsImages(*plan.manifest.colour_intrinsics, "colour", given_by(flags.colour_camera, "colour"), plan);
  if (plan.manifest.depth_intrinsics)
    CheckCameraFitsImages(*plan.manifest.depth_intrinsics, "depth", given_by(flags.depth_camera, "depth"), plan);
}

// The flags the sources' planners read (SourceFlags); each help says which
// kinds read it.
void AddImportOptions(CLI::App& app, Flags& flags) {
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
}

void AddWriterOptions(CLI::App& app, Flags& flags) {
  auto* writer = app.add_option_group("writer");
  writer
      ->add_option(
          "--codec", flags.codec,
          "chunk compression: szip (default, small) | lz4 (fastest; HDF5 filter plugin) | deflate (portable) | none")
      ->check(CLI::IsMember({"szip", "lz4", "deflate", "none"}));
  writer->add_option("--flush-interval-ms", flags.flush_interval_ms, "longest time between flushes to disk")
      ->check(CLI::Range(10, 1000));
}

int Record(const Flags& flags) {
  if (flags.out.empty() == flags.add_to.empty()) {
    throw CLI::ValidationError("--out/--add-to",
                               "give a new session directory with --out, or an existing one with --add-to");
  }
  RequireExisting(flags.scenario, "--scenario", false);
  RequireExisting(flags.description_file, "--describe", false);
  const bool adding = !flags.add_to.empty();
  SessionPlan plan = PlanSource(flags.source, flags, adding ? ReadSessionToAppendTo(flags.add_to) : SessionManifest{});
  DescribeSession(flags, plan.manifest);
  GiveCameras(flags, plan);
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
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Record a depth-camera session (HDF5 recordings + session.json).\nSOURCE:\n" + SourceDescriptions()};
  Flags flags;
  AddSessionOptions(app, flags);
  AddSimulatorOptions(app, flags);
  AddDescriptionOptions(app, flags);
  AddImportOptions(app, flags);
  AddWriterOptions(app, flags);
  return RunCli("record-session", app, argc, argv, [&] { return Record(flags); });
}
