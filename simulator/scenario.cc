#include "simulator/scenario.h"

#include "schemas/errors.h"
#include "schemas/json_fields.h"
#include "simulator/optics_presets.h"

namespace speckle::sim {

Scenario ScenarioFromJson(const nlohmann::json& json, const std::string& origin) {
  JsonFields f(json, origin);
  Scenario s;
  if (f.Has("schema_version")) {
    const int version = f.Required<int>("schema_version");
    if (version != kScenarioSchemaVersion) {
      throw SchemaVersionError(origin + ": scenario schema version " + std::to_string(version) +
                               " is not understood (this tool reads version " +
                               std::to_string(kScenarioSchemaVersion) + ")");
    }
  }
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
  if (const auto* d = f.OptionalValue("depth_model")) {
    JsonFields g(*d, f.Path("depth_model"));
    s.depth.a = g.OptionalInRange("a", s.depth.a, -0.1, -1e-5);
    s.depth.b = g.OptionalInRange("b", s.depth.b, 0.1, 100);
    s.depth.raw_noise_sigma = g.OptionalInRange("raw_noise_sigma", s.depth.raw_noise_sigma, 0, 20);
    s.depth.min_depth_m = g.OptionalInRange("min_depth_m", s.depth.min_depth_m, 0.1, 5);
    s.depth.max_raw = g.OptionalInRange("max_raw", s.depth.max_raw, 100, 2046);
    g.RejectUnknownKeys();
  }
  if (const auto* r = f.OptionalValue("rig")) {
    JsonFields g(*r, f.Path("rig"));
    s.rig.squares_x = static_cast<int>(g.OptionalInRange("squares_x", s.rig.squares_x, 3, 30));
    s.rig.squares_y = static_cast<int>(g.OptionalInRange("squares_y", s.rig.squares_y, 3, 30));
    s.rig.square_size_m = g.OptionalInRange("square_size_m", s.rig.square_size_m, 0.005, 0.2);
    s.rig.background_depth_m = g.OptionalInRange("background_depth_m", s.rig.background_depth_m, 0.5, 10);
    g.RejectUnknownKeys();
  }
  if (const auto* d = f.OptionalValue("depthboard")) {
    JsonFields g(*d, f.Path("depthboard"));
    s.depthboard.poses = static_cast<int>(g.OptionalInRange("poses", s.depthboard.poses, 0, 10000));
    s.depthboard.frames_per_pose = static_cast<int>(g.OptionalInRange("frames_per_pose", s.depthboard.frames_per_pose, 1, 100));
    s.depthboard.min_depth_m = g.OptionalInRange("min_depth_m", s.depthboard.min_depth_m, 0.3, 5);
    s.depthboard.max_depth_m = g.OptionalInRange("max_depth_m", s.depthboard.max_depth_m, 0.3, 5);
    s.depthboard.max_tilt_deg = g.OptionalInRange("max_tilt_deg", s.depthboard.max_tilt_deg, 0, 60);
    s.depthboard.seconds_between_poses = g.OptionalInRange("seconds_between_poses", s.depthboard.seconds_between_poses, 0, 600);
    g.RejectUnknownKeys();
    if (s.depthboard.min_depth_m > s.depthboard.max_depth_m) {
      throw InputError(f.Path("depthboard") + ": min_depth_m must not exceed max_depth_m");
    }
  }
  if (const auto* p = f.OptionalValue("planar")) {
    JsonFields g(*p, f.Path("planar"));
    s.planar.snapshots = static_cast<int>(g.OptionalInRange("snapshots", s.planar.snapshots, 0, 10000));
    s.planar.frames_per_snapshot = static_cast<int>(g.OptionalInRange("frames_per_snapshot", s.planar.frames_per_snapshot, 1, 100));
    s.planar.min_depth_m = g.OptionalInRange("min_depth_m", s.planar.min_depth_m, 0.3, 8);
    s.planar.max_depth_m = g.OptionalInRange("max_depth_m", s.planar.max_depth_m, 0.3, 8);
    s.planar.max_misalignment_deg = g.OptionalInRange("max_misalignment_deg", s.planar.max_misalignment_deg, 0, 20);
    g.RejectUnknownKeys();
    if (s.planar.min_depth_m > s.planar.max_depth_m) {
      throw InputError(f.Path("planar") + ": min_depth_m must not exceed max_depth_m");
    }
  }
  f.RejectUnknownKeys();
  return s;
}

nlohmann::json ToJson(const Scenario& s) {
  return {
      {"schema_version", kScenarioSchemaVersion},
      {"seed", s.seed},
      {"optics", s.optics},
      {"label", s.label},
      {"colour_noise_sigma", s.colour_noise_sigma},
      {"frame_rate_hz", s.frame_rate_hz},
      {"depth_model",
       {{"a", s.depth.a}, {"b", s.depth.b}, {"raw_noise_sigma", s.depth.raw_noise_sigma},
        {"min_depth_m", s.depth.min_depth_m}, {"max_raw", s.depth.max_raw}}},
      {"rig",
       {{"squares_x", s.rig.squares_x}, {"squares_y", s.rig.squares_y}, {"square_size_m", s.rig.square_size_m},
        {"background_depth_m", s.rig.background_depth_m}}},
      {"depthboard",
       {{"poses", s.depthboard.poses}, {"frames_per_pose", s.depthboard.frames_per_pose},
        {"min_depth_m", s.depthboard.min_depth_m}, {"max_depth_m", s.depthboard.max_depth_m},
        {"max_tilt_deg", s.depthboard.max_tilt_deg}, {"seconds_between_poses", s.depthboard.seconds_between_poses}}},
      {"planar",
       {{"snapshots", s.planar.snapshots}, {"frames_per_snapshot", s.planar.frames_per_snapshot},
        {"min_depth_m", s.planar.min_depth_m}, {"max_depth_m", s.planar.max_depth_m},
        {"max_misalignment_deg", s.planar.max_misalignment_deg}}},
  };
}

}  // namespace speckle::sim
