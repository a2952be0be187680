#include "simulator/scenario_draw.h"

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "schemas/errors.h"
#include "schemas/json_fields.h"
#include "simulator/session_simulator.h"

namespace speckle::sim {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
// Mixed into the seed so the draw has its own stream: the session's board
// poses and snapshots come from the plain seed and must not shift when a
// scenario gains a "randomize" key.
constexpr std::uint64_t kDrawStream = 0x5eedd7a3ULL;

// A range [lo, hi] within [min, max]; both ends inclusive.
template <typename T>
std::array<T, 2> Range(JsonFields& f, const std::string& key, std::array<T, 2> fallback, T min, T max) {
  if (!f.Has(key)) return fallback;
  const auto values = f.Required<std::vector<T>>(key);
  if (values.size() != 2) {
    throw InputError(f.Path(key) + ": expected [lo, hi], found " + std::to_string(values.size()) + " numbers");
  }
  if (!(values[0] >= min && values[1] <= max && values[0] <= values[1])) {
    throw InputError(f.Path(key) + ": expected " + std::to_string(min) + " <= lo <= hi <= " + std::to_string(max) +
                     ", found [" + std::to_string(values[0]) + ", " + std::to_string(values[1]) + "]");
  }
  return {values[0], values[1]};
}

SensorSpread ParseSensor(const nlohmann::json& json, const std::string& where) {
  JsonFields g(json, where);
  SensorSpread s;
  s.focal_fraction = g.OptionalInRange("focal_fraction", s.focal_fraction, 0, 0.2);
  s.principal_point_px = g.OptionalInRange("principal_point_px", s.principal_point_px, 0, 100);
  s.distortion_fraction = g.OptionalInRange("distortion_fraction", s.distortion_fraction, 0, 0.5);
  s.tangential_distortion = g.OptionalInRange("tangential_distortion", s.tangential_distortion, 0, 0.02);
  s.colour_from_ir_rotation_deg = g.OptionalInRange("colour_from_ir_rotation_deg", s.colour_from_ir_rotation_deg, 0, 5);
  s.colour_from_ir_translation_m =
      g.OptionalInRange("colour_from_ir_translation_m", s.colour_from_ir_translation_m, 0, 0.02);
  g.RejectUnknownKeys();
  return s;
}

SceneSpread ParseScene(const nlohmann::json& json, const std::string& where) {
  JsonFields g(json, where);
  SceneSpread s;
  s.background_behind_board_m = Range(g, "background_behind_board_m", s.background_behind_board_m, 0.0, 5.0);
  s.background_tilt_deg = g.OptionalInRange("background_tilt_deg", s.background_tilt_deg, 0, 45);
  s.wall_tilt_deg = g.OptionalInRange("wall_tilt_deg", s.wall_tilt_deg, 0, 20);
  s.floor_below_m = Range(g, "floor_below_m", s.floor_below_m, 0.1, 10.0);
  s.ceiling_above_m = Range(g, "ceiling_above_m", s.ceiling_above_m, 0.1, 10.0);
  s.furniture_probability = g.OptionalInRange("furniture_probability", s.furniture_probability, 0, 1);
  g.RejectUnknownKeys();
  return s;
}

SessionSpread ParseSession(const nlohmann::json& json, const std::string& where) {
  JsonFields g(json, where);
  SessionSpread s;
  s.poses = Range(g, "poses", s.poses, 0, 10000);
  s.frames_per_pose = Range(g, "frames_per_pose", s.frames_per_pose, 1, 100);
  s.snapshots = Range(g, "snapshots", s.snapshots, 0, 10000);
  s.ir_chessboard_probability = g.OptionalInRange("ir_chessboard_probability", s.ir_chessboard_probability, 0, 1);
  g.RejectUnknownKeys();
  return s;
}

class Draw {
 public:
  explicit Draw(std::uint64_t seed) {
    std::seed_seq sequence{seed, kDrawStream};
    rng_.seed(sequence);
  }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * unit_(rng_); }
  double Symmetric(double spread) { return Uniform(-spread, spread); }
  double In(const std::array<double, 2>& range) { return Uniform(range[0], range[1]); }
  int In(const std::array<int, 2>& range) { return std::uniform_int_distribution<int>(range[0], range[1])(rng_); }
  // A unit vector in a uniformly random direction.
  Eigen::Vector3d Direction() {
    std::normal_distribution<double> normal;
    Eigen::Vector3d d(normal(rng_), normal(rng_), normal(rng_));
    return d.norm() > 1e-12 ? d.normalized() : Eigen::Vector3d::UnitX();
  }

 private:
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> unit_{0, 1};
};

// One unit off the production line: both focal lengths scale together (the
// pixel aspect ratio is fixed by the sensor), the principal point moves with
// the lens mounting, and the lens grinding varies the distortion.
CameraOverride DrawCamera(const CameraModel& nominal, const SensorSpread& s, Draw& draw) {
  const double focal_scale = 1 + draw.Symmetric(s.focal_fraction);
  CameraOverride out;
  out.intrinsics = std::array<double, 4>{nominal.fx * focal_scale, nominal.fy * focal_scale,
                                         nominal.cx + draw.Symmetric(s.principal_point_px),
                                         nominal.cy + draw.Symmetric(s.principal_point_px)};
  std::array<double, 5> k = nominal.distortion;
  for (const int radial : {0, 1, 4}) k[radial] *= 1 + draw.Symmetric(s.distortion_fraction);
  for (const int tangential : {2, 3}) k[tangential] += draw.Symmetric(s.tangential_distortion);
  out.distortion = k;
  return out;
}

void DrawSensor(const SensorSpread& s, Draw& draw, Scenario& scenario) {
  const SensorOptics nominal = OpticsFor(scenario);
  scenario.colour_camera = DrawCamera(nominal.colour, s, draw);
  scenario.ir_camera = DrawCamera(nominal.ir, s, draw);
  const Eigen::AngleAxisd turn(draw.Uniform(0, s.colour_from_ir_rotation_deg) * kDegToRad, draw.Direction());
  const Eigen::AngleAxisd rotation(turn * nominal.colour_from_ir.linear());
  const Eigen::Vector3d rotation_deg = rotation.axis() * rotation.angle() / kDegToRad;
  scenario.colour_from_ir_rotation_deg = std::array<double, 3>{rotation_deg.x(), rotation_deg.y(), rotation_deg.z()};
  std::array<double, 3> t{};
  for (int i = 0; i < 3; ++i)
    t[i] = nominal.colour_from_ir.translation()[i] + draw.Symmetric(s.colour_from_ir_translation_m);
  scenario.colour_from_ir_m = t;
}

void DrawScene(const SceneSpread& s, Draw& draw, Scenario& scenario) {
  scenario.rig.background_behind_board_m = draw.In(s.background_behind_board_m);
  // A tilt of up to background_tilt_deg about a random axis in the wall.
  const double tilt = draw.Uniform(0, s.background_tilt_deg), heading = draw.Uniform(0, 2 * M_PI);
  scenario.rig.background_tilt_deg = {tilt * std::cos(heading), tilt * std::sin(heading)};
  if (s.wall_tilt_deg > 0 && !scenario.effects.contains("misaligned_snapshots")) {
    scenario.effects["misaligned_snapshots"] = {{"max_tilt_deg", s.wall_tilt_deg}};
  }
  scenario.room.floor_below_m = draw.In(s.floor_below_m);
  scenario.room.ceiling_above_m = draw.In(s.ceiling_above_m);
  scenario.planar.furniture_probability = s.furniture_probability;
}

void DrawSession(const SessionSpread& s, Draw& draw, Scenario& scenario) {
  scenario.depthboard.poses = draw.In(s.poses);
  scenario.depthboard.frames_per_pose = draw.In(s.frames_per_pose);
  scenario.planar.snapshots = draw.In(s.snapshots);
  if (draw.Uniform(0, 1) >= s.ir_chessboard_probability) scenario.ir_chessboard.poses = 0;
}

}  // namespace

RandomizeSpec RandomizeSpecFromJson(const nlohmann::json& json, const std::string& where) {
  JsonFields f(json, where);
  RandomizeSpec spec;
  if (const auto* s = f.OptionalValue("sensor")) spec.sensor = ParseSensor(*s, f.Path("sensor"));
  if (const auto* s = f.OptionalValue("scene")) spec.scene = ParseScene(*s, f.Path("scene"));
  if (const auto* s = f.OptionalValue("session")) spec.session = ParseSession(*s, f.Path("session"));
  f.RejectUnknownKeys();
  return spec;
}

nlohmann::json ToJson(const RandomizeSpec& spec) {
  const SensorSpread& a = spec.sensor;
  const SceneSpread& b = spec.scene;
  const SessionSpread& c = spec.session;
  return {{"sensor",
           {{"focal_fraction", a.focal_fraction},
            {"principal_point_px", a.principal_point_px},
            {"distortion_fraction", a.distortion_fraction},
            {"tangential_distortion", a.tangential_distortion},
            {"colour_from_ir_rotation_deg", a.colour_from_ir_rotation_deg},
            {"colour_from_ir_translation_m", a.colour_from_ir_translation_m}}},
          {"scene",
           {{"background_behind_board_m", b.background_behind_board_m},
            {"background_tilt_deg", b.background_tilt_deg},
            {"wall_tilt_deg", b.wall_tilt_deg},
            {"floor_below_m", b.floor_below_m},
            {"ceiling_above_m", b.ceiling_above_m},
            {"furniture_probability", b.furniture_probability}}},
          {"session",
           {{"poses", c.poses},
            {"frames_per_pose", c.frames_per_pose},
            {"snapshots", c.snapshots},
            {"ir_chessboard_probability", c.ir_chessboard_probability}}}};
}

void DrawScenario(const RandomizeSpec& spec, Scenario& scenario) {
  Draw draw(scenario.seed);
  DrawSensor(spec.sensor, draw, scenario);
  DrawScene(spec.scene, draw, scenario);
  DrawSession(spec.session, draw, scenario);
  scenario.drawn_from = ToJson(spec);
}

}  // namespace speckle::sim
