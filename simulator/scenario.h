#pragma once
// A simulated session: sensor, rig, depth formation, effects and the
// recordings to make. Every key but an effect's parameters has a default, so
// "{}" is a valid scenario; unknown keys, wrong types and out-of-range values
// are rejected with the key's path.
//
// "randomize": {...} (simulator/scenario_draw.h) draws the sensor, scene and
// session from spreads around these values with the scenario's seed; the
// parsed Scenario then holds the drawn, concrete values, and ToJson writes
// them (with the spreads under "drawn_from", kept for the record but never
// drawn from again), so a recording's scenario_json is the session's truth.
#include <array>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace speckle::sim {

inline constexpr int kScenarioSchemaVersion = 1;

// The true relation between depth z (metres) and raw value r.
enum class BaseForm {
  kReciprocal,  // z = 1 / (a r + b)                 (Burrus; thesis fit by default)
  kTangent,     // z = c tan(r / k + b)              (Magnenat; thesis fit)
  kDisparity,   // z = baseline f / ((doff - r) / 8) (ROS kinect_calibration)
};

struct DepthFormation {
  BaseForm form = BaseForm::kReciprocal;
  double a = -0.0027681, b = 3.0163;                       // reciprocal
  double tan_c = 0.15257, tan_k = 2431.3, tan_b = 1.1200;  // tangent
  double baseline_m = 0.075, focal_px = 580, doff = 1090;  // disparity
  double raw_noise_sigma = 0.6;                            // raw units, before rounding to integers
  double min_depth_m = 0.45;                               // nearer than this: no reading (2047)
  double max_raw = 1080;                                   // beyond the asymptote: no reading
  // What the driver reports. false: libfreenect's raw values (2047 = no
  // reading). true: the OpenNI driver's millimetres (0 = no reading), its
  // factory conversion of each raw value: mm = 1000 (DepthFromRaw(raw) -
  // mm_offset_m) / mm_gain, rounded. The true depth of a reported value is
  // then the linear_mm form z = (mm_gain / 1000) mm + mm_offset_m; a gain or
  // offset other than 1 and 0 is a factory conversion that is off (the
  // thesis's App. C: right only for the stock optics).
  bool millimetre = false;
  double mm_gain = 1, mm_offset_m = 0;

  double RawFromDepth(double z_m) const;
  double DepthFromRaw(double raw) const;
};

// Overrides of the optics preset's cameras (thesis Appendix A by default).
struct CameraOverride {
  std::optional<std::array<double, 4>> intrinsics;  // fx, fy, cx, cy
  std::optional<std::array<double, 5>> distortion;  // k1, k2, p1, p2, k3
};

struct RigSpec {
  int squares_x = 11;
  int squares_y = 8;
  double square_size_m = 0.0223;
  double background_depth_m = 3.2;  // the wall behind the board (a sharp depth step)
  // When > 0, the wall stands this far behind each board pose's centre
  // instead (a board held or mounted in front of a wall, as users record):
  // background_depth_m is then unused.
  double background_behind_board_m = 0;
  // The wall's rotation about the IR camera's x and y axes (degrees): a wall
  // is rarely square to a hand-held sensor.
  std::array<double, 2> background_tilt_deg{0, 0};
};

struct RoomSpec {
  double floor_below_m = 0.8;  // the floor enters the view at distance
  double ceiling_above_m = 1.6;
};

struct DepthboardSpec {
  // The colour camera is calibrated from one view per pose: with 30 views of
  // this small board its principal point stays off by a pixel or two, and the
  // diagnosis rightly reports the rotation-like depth error that leaves.
  int poses = 60;
  int frames_per_pose = 3;
  double min_depth_m = 0.6;
  double max_depth_m = 1.5;
  double max_tilt_deg = 30;
  double seconds_between_poses = 20;
};

struct PlanarSpec {
  int snapshots = 12;
  int frames_per_snapshot = 2;
  double min_depth_m = 0.6;
  double max_depth_m = 3.0;
  double clutter_probability = 0.3;  // chance of an object inside the minimum range
  // Chance of furniture (a box on the floor, within range and in front of
  // the wall) entering a snapshot: planar cleanup must drop it.
  double furniture_probability = 0;
};

struct IrChessboardSpec {
  // IR intrinsics set every depth's offset through the extrinsics: be
  // generous. With 30 views of this small board the IR principal point stays
  // off by 1.4 px (one sigma), which the extrinsics turn into a rotation and
  // the depths into a tilt linear in image x and y; 60 views bring it to
  // about 0.9 px.
  int poses = 60;
  int frames_per_pose = 1;
};

struct Scenario {
  std::uint64_t seed = 1;
  std::string optics = "stock";
  std::string label = "simulated";
  double colour_noise_sigma = 2.0;  // grey levels
  double frame_rate_hz = 30;
  CameraOverride colour_camera, ir_camera;
  std::optional<std::array<double, 3>> colour_from_ir_m;  // translation
  // Rotation vector (axis times angle, degrees) of colour from IR; the
  // presets have parallel optical axes.
  std::optional<std::array<double, 3>> colour_from_ir_rotation_deg;
  std::optional<std::array<double, 3>> projector_in_ir_m;
  DepthFormation depth;
  RigSpec rig;
  RoomSpec room;
  DepthboardSpec depthboard;
  PlanarSpec planar;
  IrChessboardSpec ir_chessboard;
  // Effect name -> parameters, with defaults filled in once parsed.
  nlohmann::json effects = nlohmann::json::object();
  // The "randomize" spreads the concrete values above were drawn from (null
  // when nothing was drawn): a record of provenance, never drawn from again.
  nlohmann::json drawn_from = nullptr;
};

// `origin` names the file in messages. Throws InputError.
Scenario ScenarioFromJson(const nlohmann::json& json, const std::string& origin);
nlohmann::json ToJson(const Scenario& scenario);
std::string ToString(BaseForm form);

}  // namespace speckle::sim
