#include "simulator/scenario.h"

#include <Eigen/Core>
#include <cmath>

#include "schemas/errors.h"
#include "schemas/json_fields.h"
#include "simulator/optics_presets.h"
#include "simulator/scenario_draw.h"
#include "simulator/sim_effect.h"

namespace speckle::sim {

std::string ToString(BaseForm form) {
  switch (form) {
    case BaseForm::kReciprocal:
      return "reciprocal";
    case BaseForm::kTangent:
      return "tangent";
    case BaseForm::kDisparity:
      return "disparity";
  }
  return "?";
}

double DepthFormation::RawFromDepth(double z) const {
  switch (form) {
    case BaseForm::kReciprocal:
      return (1.0 / z - b) / a;
    case BaseForm::kTangent:
      return tan_k * (std::atan(z / tan_c) - tan_b);
    case BaseForm::kDisparity:
      return doff - 8 * baseline_m * focal_px / z;
  }
  return 0;
}

double DepthFormation::DepthFromRaw(double r) const {
  switch (form) {
    case BaseForm::kReciprocal:
      return 1.0 / (a * r + b);
    case BaseForm::kTangent:
      return tan_c * std::tan(r / tan_k + tan_b);
    case BaseForm::kDisparity:
      return 8 * baseline_m * focal_px / (doff - r);
  }
  return 0;
}

namespace {

template <std::size_t N>
std::optional<std::array<double, N>> OptionalArray(JsonFields& f, const std::string& key) {
  if (!f.Has(key)) return std::nullopt;
  const auto values = f.Required<std::vector<double>>(key);
  if (values.size() != N) {
    throw InputError(f.Path(key) + ": expected " + std::to_string(N) + " numbers, found " +
                     std::to_string(values.size()));
  }
  std::array<double, N> out{};
  std::copy(values.begin(), values.end(), out.begin());
  return out;
}

CameraOverride ParseCamera(const nlohmann::json& json, const std::string& where) {
  JsonFields f(json, where);
  CameraOverride c;
  c.intrinsics = OptionalArray<4>(f, "intrinsics");
  c.distortion = OptionalArray<5>(f, "distortion");
  f.RejectUnknownKeys();
  return c;
}

nlohmann::json CameraToJson(const CameraOverride& c) {
  nlohmann::json j = nlohmann::json::object();
  if (c.intrinsics) j["intrinsics"] = *c.intrinsics;
  if (c.distortion) j["distortion"] = *c.distortion;
  return j;
}

int Count(JsonFields& g, const std::string& key, int fallback, int hi) {
  return static_cast<int>(g.OptionalInRange(key, fallback, 0, hi));
}

RigSpec ParseRig(const nlohmann::json& json, const std::string& where) {
  JsonFields g(json, where);
  RigSpec rig;
  rig.squares_x = static_cast<int>(g.OptionalInRange("squares_x", rig.squares_x, 3, 30));
  rig.squares_y = static_cast<int>(g.OptionalInRange("squares_y", rig.squares_y, 3, 30));
  rig.square_size_m = g.OptionalInRange("square_size_m", rig.square_size_m, 0.005, 0.2);
  rig.background_depth_m = g.OptionalInRange("background_depth_m", rig.background_depth_m, 0.5, 10);
  rig.background_behind_board_m = g.OptionalInRange("background_behind_board_m", rig.background_behind_board_m, 0, 5);
  if (const auto tilt = OptionalArray<2>(g, "background_tilt_deg")) {
    for (const double angle : *tilt) {
      if (!(std::abs(angle) <= 60))
        throw InputError(g.Path("background_tilt_deg") + ": expected angles within +-60 degrees");
    }
    rig.background_tilt_deg = *tilt;
  }
  g.RejectUnknownKeys();
  return rig;
}

PlanarSpec ParsePlanar(const nlohmann::json& json, const std::string& where) {
  JsonFields g(json, where);
  PlanarSpec w;
  w.snapshots = Count(g, "snapshots", w.snapshots, 10000);
  w.frames_per_snapshot = std::max(1, Count(g, "frames_per_snapshot", w.frames_per_snapshot, 100));
  w.min_depth_m = g.OptionalInRange("min_depth_m", w.min_depth_m, 0.3, 8);
  w.max_depth_m = g.OptionalInRange("max_depth_m", w.max_depth_m, 0.3, 8);
  w.clutter_probability = g.OptionalInRange("clutter_probability", w.clutter_probability, 0, 1);
  w.furniture_probability = g.OptionalInRange("furniture_probability", w.furniture_probability, 0, 1);
  g.RejectUnknownKeys();
  if (w.min_depth_m > w.max_depth_m) throw InputError(where + ": min_depth_m must not exceed max_depth_m");
  return w;
}

// The cameras' overrides: intrinsics, distortion and the rig between them.
void ParseCameras(const nlohmann::json& json, const std::string& where, Scenario& s) {
  JsonFields g(json, where);
  if (const auto* colour = g.OptionalValue("colour")) s.colour_camera = ParseCamera(*colour, g.Path("colour"));
  if (const auto* ir = g.OptionalValue("ir")) s.ir_camera = ParseCamera(*ir, g.Path("ir"));
  // Offsets within the sensor's body (a Kinect's projector sits 7.5 cm from
  // its IR camera): half a metre is generous, a kilometre a typo in units.
  for (const char* offset : {"colour_from_ir_m", "projector_in_ir_m"}) {
    const auto value = OptionalArray<3>(g, offset);
    if (value && !(Eigen::Vector3d::Map(value->data()).norm() <= 0.5))
      throw InputError(g.Path(offset) + ": expected an offset within the sensor, at most 0.5 m (metres, not mm)");
    (std::string(offset) == "colour_from_ir_m" ? s.colour_from_ir_m : s.projector_in_ir_m) = value;
  }
  s.colour_from_ir_rotation_deg = OptionalArray<3>(g, "colour_from_ir_rotation_deg");
  if (s.colour_from_ir_rotation_deg && !(Eigen::Vector3d::Map(s.colour_from_ir_rotation_deg->data()).norm() <= 10)) {
    throw InputError(g.Path("colour_from_ir_rotation_deg") + ": expected a rotation of at most 10 degrees");
  }
  g.RejectUnknownKeys();
}

// The base form's constants, each form with its own keys.
void ParseBaseForm(JsonFields& g, DepthFormation& m) {
  const std::string form = g.Optional<std::string>("form", "reciprocal");
  if (form == "reciprocal") {
    m.form = BaseForm::kReciprocal;
    m.a = g.OptionalInRange("a", m.a, -0.1, -1e-5);
    m.b = g.OptionalInRange("b", m.b, 0.1, 100);
  } else if (form == "tangent") {
    m.form = BaseForm::kTangent;
    m.tan_c = g.OptionalInRange("c", m.tan_c, 0.01, 10);
    m.tan_k = g.OptionalInRange("k", m.tan_k, 100, 1e5);
    m.tan_b = g.OptionalInRange("b", m.tan_b, 0, 1.57);
  } else if (form == "disparity") {
    m.form = BaseForm::kDisparity;
    m.baseline_m = g.OptionalInRange("baseline_m", m.baseline_m, 0.01, 1);
    m.focal_px = g.OptionalInRange("focal_px", m.focal_px, 50, 5000);
    m.doff = g.OptionalInRange("doff", m.doff, 500, 5000);
  } else {
    throw InputError(g.Path("form") + ": expected reciprocal, tangent or disparity, found \"" + form + "\"");
  }
}

// `m` holds the defaults the keys override.
DepthFormation ParseDepthModel(const nlohmann::json& json, const std::string& where, DepthFormation m) {
  JsonFields g(json, where);
  ParseBaseForm(g, m);
  m.raw_noise_sigma = g.OptionalInRange("raw_noise_sigma", m.raw_noise_sigma, 0, 20);
  m.min_depth_m = g.OptionalInRange("min_depth_m", m.min_depth_m, 0.1, 5);
  m.max_raw = g.OptionalInRange("max_raw", m.max_raw, 100, 2046);
  const std::string units = g.Optional<std::string>("units", "raw_11bit");
  if (units != "raw_11bit" && units != "millimetre") {
    throw InputError(g.Path("units") + ": expected raw_11bit or millimetre, found \"" + units + "\"");
  }
  m.millimetre = units == "millimetre";
  m.mm_gain = g.OptionalInRange("mm_gain", m.mm_gain, 0.5, 2);
  m.mm_offset_m = g.OptionalInRange("mm_offset_m", m.mm_offset_m, -0.5, 0.5);
  g.RejectUnknownKeys();
  return m;
}

RoomSpec ParseRoom(const nlohmann::json& json, const std::string& where, RoomSpec room) {
  JsonFields g(json, where);
  room.floor_below_m = g.OptionalInRange("floor_below_m", room.floor_below_m, 0.1, 10);
  room.ceiling_above_m = g.OptionalInRange("ceiling_above_m", room.ceiling_above_m, 0.1, 10);
  g.RejectUnknownKeys();
  return room;
}

DepthboardSpec ParseDepthboard(const nlohmann::json& json, const std::string& where, DepthboardSpec b) {
  JsonFields g(json, where);
  b.poses = Count(g, "poses", b.poses, 10000);
  b.frames_per_pose = std::max(1, Count(g, "frames_per_pose", b.frames_per_pose, 100));
  b.min_depth_m = g.OptionalInRange("min_depth_m", b.min_depth_m, 0.3, 5);
  b.max_depth_m = g.OptionalInRange("max_depth_m", b.max_depth_m, 0.3, 5);
  b.max_tilt_deg = g.OptionalInRange("max_tilt_deg", b.max_tilt_deg, 0, 60);
  b.seconds_between_poses = g.OptionalInRange("seconds_between_poses", b.seconds_between_poses, 0, 600);
  g.RejectUnknownKeys();
  if (b.min_depth_m > b.max_depth_m) throw InputError(where + ": min_depth_m must not exceed max_depth_m");
  return b;
}

IrChessboardSpec ParseIrChessboard(const nlohmann::json& json, const std::string& where, IrChessboardSpec ir) {
  JsonFields g(json, where);
  ir.poses = Count(g, "poses", ir.poses, 10000);
  ir.frames_per_pose = std::max(1, Count(g, "frames_per_pose", ir.frames_per_pose, 100));
  g.RejectUnknownKeys();
  return ir;
}

// Each effect is built once: that checks its parameters and gives the
// defaults to record as truth.
nlohmann::json ParseEffects(const nlohmann::json& json, const std::string& where, std::uint64_t seed) {
  nlohmann::json effects = nlohmann::json::object();
  const auto built = BuildSimEffects(json, where, {seed, 640, 480});
  std::size_t i = 0;
  for (const auto& [name, parameters] : json.items()) effects[name] = built[i++]->Parameters();
  return effects;
}

void CheckSchemaVersion(JsonFields& f, const std::string& origin) {
  if (!f.Has("schema_version")) return;
  const int version = f.Required<int>("schema_version");
  if (version != kScenarioSchemaVersion) {
    throw SchemaVersionError(origin + ": scenario schema version " + std::to_string(version) +
                             " is not understood (this tool reads version " + std::to_string(kScenarioSchemaVersion) +
                             ")");
  }
}

}  // namespace

Scenario ScenarioFromJson(const nlohmann::json& json, const std::string& origin) {
  JsonFields f(json, origin);
  Scenario s;
  CheckSchemaVersion(f, origin);
  s.seed = f.Optional<std::uint64_t>("seed", s.seed);
  s.optics = f.Optional<std::string>("optics", s.optics);
  try {
    OpticsByName(s.optics);
  } catch (const InputError& e) {
    throw InputError(f.Path("optics") + ": " + e.what());
  }
  s.label = f.Optional<std::string>("label", s.label);
  s.colour_noise_sigma = f.OptionalInRange("colour_noise_sigma", s.colour_noise_sigma, 0, 50);
  s.frame_rate_hz = f.OptionalInRange("frame_rate_hz", s.frame_rate_hz, 1, 120);
  if (const auto* c = f.OptionalValue("cameras")) ParseCameras(*c, f.Path("cameras"), s);
  if (const auto* d = f.OptionalValue("depth_model")) s.depth = ParseDepthModel(*d, f.Path("depth_model"), s.depth);
  if (const auto* r = f.OptionalValue("rig")) s.rig = ParseRig(*r, f.Path("rig"));
  if (const auto* r = f.OptionalValue("room")) s.room = ParseRoom(*r, f.Path("room"), s.room);
  if (const auto* d = f.OptionalValue("depthboard"))
    s.depthboard = ParseDepthboard(*d, f.Path("depthboard"), s.depthboard);
  if (const auto* p = f.OptionalValue("planar")) s.planar = ParsePlanar(*p, f.Path("planar"));
  if (const auto* p = f.OptionalValue("ir_chessboard"))
    s.ir_chessboard = ParseIrChessboard(*p, f.Path("ir_chessboard"), s.ir_chessboard);
  if (const auto* e = f.OptionalValue("effects")) s.effects = ParseEffects(*e, f.Path("effects"), s.seed);
  if (const auto* d = f.OptionalValue("drawn_from")) s.drawn_from = *d;
  if (const auto* r = f.OptionalValue("randomize")) {
    if (!s.drawn_from.is_null()) {
      throw InputError(f.Path("randomize") + ": a scenario already drawn (it has drawn_from) is not drawn again");
    }
    DrawScenario(RandomizeSpecFromJson(*r, f.Path("randomize")), s);
  }
  f.RejectUnknownKeys();
  return s;
}

nlohmann::json ToJson(const Scenario& s) {
  nlohmann::json depth = {{"form", ToString(s.depth.form)},
                          {"raw_noise_sigma", s.depth.raw_noise_sigma},
                          {"min_depth_m", s.depth.min_depth_m},
                          {"max_raw", s.depth.max_raw}};
  // Raw sessions' scenarios stay as they were (recorded truths compare equal).
  if (s.depth.millimetre)
    depth.update({{"units", "millimetre"}, {"mm_gain", s.depth.mm_gain}, {"mm_offset_m", s.depth.mm_offset_m}});
  switch (s.depth.form) {
    case BaseForm::kReciprocal:
      depth.update({{"a", s.depth.a}, {"b", s.depth.b}});
      break;
    case BaseForm::kTangent:
      depth.update({{"c", s.depth.tan_c}, {"k", s.depth.tan_k}, {"b", s.depth.tan_b}});
      break;
    case BaseForm::kDisparity:
      depth.update({{"baseline_m", s.depth.baseline_m}, {"focal_px", s.depth.focal_px}, {"doff", s.depth.doff}});
      break;
  }
  nlohmann::json cameras = {{"colour", CameraToJson(s.colour_camera)}, {"ir", CameraToJson(s.ir_camera)}};
  if (s.colour_from_ir_m) cameras["colour_from_ir_m"] = *s.colour_from_ir_m;
  if (s.projector_in_ir_m) cameras["projector_in_ir_m"] = *s.projector_in_ir_m;
  if (s.colour_from_ir_rotation_deg) cameras["colour_from_ir_rotation_deg"] = *s.colour_from_ir_rotation_deg;
  nlohmann::json json = {
      {"schema_version", kScenarioSchemaVersion},
      {"seed", s.seed},
      {"optics", s.optics},
      {"label", s.label},
      {"colour_noise_sigma", s.colour_noise_sigma},
      {"frame_rate_hz", s.frame_rate_hz},
      {"cameras", cameras},
      {"depth_model", depth},
      {"rig",
       {{"squares_x", s.rig.squares_x},
        {"squares_y", s.rig.squares_y},
        {"square_size_m", s.rig.square_size_m},
        {"background_depth_m", s.rig.background_depth_m},
        {"background_behind_board_m", s.rig.background_behind_board_m},
        {"background_tilt_deg", s.rig.background_tilt_deg}}},
      {"room", {{"floor_below_m", s.room.floor_below_m}, {"ceiling_above_m", s.room.ceiling_above_m}}},
      {"depthboard",
       {{"poses", s.depthboard.poses},
        {"frames_per_pose", s.depthboard.frames_per_pose},
        {"min_depth_m", s.depthboard.min_depth_m},
        {"max_depth_m", s.depthboard.max_depth_m},
        {"max_tilt_deg", s.depthboard.max_tilt_deg},
        {"seconds_between_poses", s.depthboard.seconds_between_poses}}},
      {"planar",
       {{"snapshots", s.planar.snapshots},
        {"frames_per_snapshot", s.planar.frames_per_snapshot},
        {"min_depth_m", s.planar.min_depth_m},
        {"max_depth_m", s.planar.max_depth_m},
        {"clutter_probability", s.planar.clutter_probability},
        {"furniture_probability", s.planar.furniture_probability}}},
      {"ir_chessboard", {{"poses", s.ir_chessboard.poses}, {"frames_per_pose", s.ir_chessboard.frames_per_pose}}},
      {"effects", s.effects},
  };
  if (!s.drawn_from.is_null()) json["drawn_from"] = s.drawn_from;
  return json;
}

}  // namespace speckle::sim
