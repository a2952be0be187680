#pragma once
// Randomized scenarios: a tool tuned on one simulated sensor in one room
// learns that sensor and that room. The "randomize" key of a scenario draws,
// from the scenario's seed, a sensor from a manufacturing spread around the
// preset (plus any camera overrides), a room and a user-like session, and
// writes the drawn values into the Scenario, so the stored scenario_json of
// each recording is the concrete truth of that session.
//
//   "randomize": {
//     "sensor":  {"focal_fraction": 0.02, "principal_point_px": 15,
//                 "distortion_fraction": 0.08, "tangential_distortion": 0.001,
//                 "colour_from_ir_rotation_deg": 0.5, "colour_from_ir_translation_m": 0.003},
//     "scene":   {"background_behind_board_m": [0.4, 0.9], "background_tilt_deg": 20,
//                 "wall_tilt_deg": 2, "floor_below_m": [0.6, 1.2], "ceiling_above_m": [0.9, 1.6],
//                 "furniture_probability": 0.4},
//     "session": {"poses": [15, 25], "frames_per_pose": [1, 3], "snapshots": [16, 24],
//                 "ir_chessboard_probability": 0}
//   }
//
// Every key is optional ("randomize": {} draws with the defaults above); a
// spread of 0 (or a range [x, x]) keeps that value fixed. All draws are
// uniform, so every drawn value lies within its stated spread:
//   - focal lengths fx, fy of colour and IR: preset x (1 +- focal_fraction);
//   - principal points: preset +- principal_point_px (each axis);
//   - radial k1, k2, k3: preset x (1 +- distortion_fraction), each
//     independently (relative, so wide-angle and stock lenses vary alike);
//     tangential p1, p2: preset +- tangential_distortion;
//   - colour from IR: a rotation of up to colour_from_ir_rotation_deg about a
//     random axis, the translation +- colour_from_ir_translation_m per axis;
//   - background_behind_board_m and the background's tilt (up to
//     background_tilt_deg about a random axis in the wall) set rig's keys of
//     the same names; wall_tilt_deg becomes the misaligned_snapshots effect's
//     max_tilt_deg (unless the scenario lists that effect itself), so each
//     wall snapshot's tilt is in its frames' /truth/ir_from_target;
//   - floor_below_m, ceiling_above_m set room's keys; furniture_probability
//     (not drawn: a per-snapshot chance) sets planar.furniture_probability;
//   - ranges [lo, hi] are drawn uniformly (integers inclusive);
//   - IR chessboard recording kept with ir_chessboard_probability, else none.
//
// Common mistake: drawing again from a stored scenario. ToJson writes the
// spreads under "drawn_from", which the reader keeps but never draws from.
#include <array>
#include <nlohmann/json.hpp>
#include <string>

#include "simulator/scenario.h"

namespace speckle::sim {

struct SensorSpread {
  double focal_fraction = 0.02;
  double principal_point_px = 15;
  double distortion_fraction = 0.08;     // relative, k1 k2 k3
  double tangential_distortion = 0.001;  // absolute, p1 p2
  double colour_from_ir_rotation_deg = 0.5;
  double colour_from_ir_translation_m = 0.003;
};

struct SceneSpread {
  std::array<double, 2> background_behind_board_m{0.4, 0.9};
  double background_tilt_deg = 20;
  double wall_tilt_deg = 2;
  std::array<double, 2> floor_below_m{0.6, 1.2};
  std::array<double, 2> ceiling_above_m{0.9, 1.6};
  double furniture_probability = 0.4;
};

struct SessionSpread {
  std::array<int, 2> poses{15, 25};
  std::array<int, 2> frames_per_pose{1, 3};
  std::array<int, 2> snapshots{16, 24};
  double ir_chessboard_probability = 0;
};

struct RandomizeSpec {
  SensorSpread sensor;
  SceneSpread scene;
  SessionSpread session;
};

// `where` names the key in messages ("scenario.json.randomize"). Throws
// InputError for unknown keys, wrong types and out-of-range spreads.
RandomizeSpec RandomizeSpecFromJson(const nlohmann::json& json, const std::string& where);
nlohmann::json ToJson(const RandomizeSpec& spec);

// Draws from `scenario.seed` (its own random stream: the session's poses are
// unchanged by it) and writes the concrete values into `scenario`, with
// scenario.drawn_from = ToJson(spec).
void DrawScenario(const RandomizeSpec& spec, Scenario& scenario);

}  // namespace speckle::sim
