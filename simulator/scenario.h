#pragma once
// A simulated session: sensor, rig, depth formation and the recordings to
// make. Every key has a default, so "{}" is a valid scenario; unknown keys,
// wrong types and out-of-range values are rejected with the key's path.
#include <nlohmann/json.hpp>
#include <string>

namespace speckle::sim {

inline constexpr int kScenarioSchemaVersion = 1;

struct DepthFormation {
  // Reciprocal base form z = 1 / (a r + b): the thesis's stock-optics fit.
  double a = -0.0027681;
  double b = 3.0163;
  double raw_noise_sigma = 0.6;  // raw units, before rounding to integers
  double min_depth_m = 0.45;     // nearer than this: no reading (2047)
  double max_raw = 1080;         // beyond the asymptote: no reading
};

struct RigSpec {
  int squares_x = 11;
  int squares_y = 8;
  double square_size_m = 0.0223;
  double background_depth_m = 3.2;  // the wall behind the board (a sharp depth step)
};

struct DepthboardSpec {
  int poses = 30;
  int frames_per_pose = 3;
  double min_depth_m = 0.6;
  double max_depth_m = 1.5;
  double max_tilt_deg = 30;
  double seconds_between_poses = 5;
};

struct PlanarSpec {
  int snapshots = 12;
  int frames_per_snapshot = 2;
  double min_depth_m = 0.6;
  double max_depth_m = 3.0;
  double max_misalignment_deg = 1.0;
};

struct Scenario {
  std::uint64_t seed = 1;
  std::string optics = "stock";
  std::string label = "simulated";
  double colour_noise_sigma = 2.0;  // grey levels
  double frame_rate_hz = 30;
  DepthFormation depth;
  RigSpec rig;
  DepthboardSpec depthboard;
  PlanarSpec planar;
};

// `origin` names the file in messages. Throws InputError.
Scenario ScenarioFromJson(const nlohmann::json& json, const std::string& origin);
nlohmann::json ToJson(const Scenario& scenario);

}  // namespace speckle::sim
