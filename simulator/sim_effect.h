#pragma once
// A physical effect the simulator can switch on. Each effect is one header in
// simulator/effects/ that ends with SPECKLE_SIM_EFFECT(ClassName); the build
// collects that folder, so adding an effect touches no other file.
//
// Recipe for a new effect:
//  1. Copy the shortest header in simulator/effects/ (thermal_drift.h).
//  2. Set kName (the scenario key) and kDoc (one line: what physics it models).
//  3. Read parameters in the constructor with JsonFields (ranges are checked,
//     unknown keys are rejected for you) and echo them in Parameters().
//  4. Override the hooks it needs: MoveTarget, DepthGridShift, RawOffset.
//  5. Add a test to tests/sim_effects_test.cc proving the data change the
//     physics predicts, and a scenario under examples/scenarios/.
#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "schemas/json_fields.h"

namespace speckle::sim {

struct TargetPose {
  // Target coordinates -> IR camera coordinates (metres). The target is the
  // plane z = 0; a board occupies [0, width] x [0, height] of it.
  Eigen::Isometry3d ir_from_target = Eigen::Isometry3d::Identity();
  bool is_board = true;  // false: an unbounded wall filling the view
};

enum class SimRecording { kDepthboard, kPlanar, kIrChessboard };

// The frame being rendered.
struct FrameContext {
  SimRecording recording = SimRecording::kDepthboard;
  int pose = 0;                  // still pose or wall snapshot
  double time_s = 0;             // since the session started (colour exposure)
  double seconds_into_pose = 0;  // since this pose started
  std::uint64_t seed = 0;        // scenario seed
};

// One depth pixel while its raw value is formed.
struct DepthSample {
  int u = 0, v = 0;     // depth pixel
  double x = 0, y = 0;  // normalized undistorted IR coordinates of its ray
  double z_m = 0;       // true depth
  double raw = 0;       // ideal raw value from the base form (continuous)
  double albedo = 1;    // IR reflectivity of the surface hit (0..1)
  double time_s = 0;
};

// Fixed facts about the session an effect may need when it is built.
struct SceneContext {
  std::uint64_t seed = 0;
  int width = 640, height = 480;  // depth image
};

class SimEffect {
 public:
  virtual ~SimEffect() = default;
  // Parameters with defaults filled in, written to the recording's /truth.
  virtual nlohmann::json Parameters() const = 0;
  // Where the target is when the colour and the depth images are exposed.
  virtual void MoveTarget(const FrameContext&, TargetPose& colour_pose, TargetPose& depth_pose) const {}
  // Offset of the depth image's pixel grid from the IR camera's, in pixels.
  virtual Eigen::Vector2d DepthGridShift() const { return Eigen::Vector2d::Zero(); }
  // Added to the raw value before noise and rounding.
  virtual double RawOffset(const DepthSample&) const { return 0; }
};

struct SimEffectInfo {
  std::string name;
  std::string doc;
  std::function<std::unique_ptr<SimEffect>(JsonFields&, const SceneContext&)> create;
};

bool RegisterSimEffect(SimEffectInfo info);
// Every registered effect, sorted by name.
std::vector<SimEffectInfo> SimEffectCatalogue();
// Builds the effects a scenario's "effects" object names. Throws InputError
// naming an unknown effect, a missing or out-of-range parameter, or an
// unknown key.
std::vector<std::unique_ptr<SimEffect>> BuildSimEffects(const nlohmann::json& effects, const std::string& where,
                                                        const SceneContext& context);

#define SPECKLE_SIM_EFFECT(Class)                                                                            \
  inline const bool kSimEffectRegistered_##Class = ::speckle::sim::RegisterSimEffect(                        \
      {Class::kName, Class::kDoc, [](::speckle::JsonFields& fields, const ::speckle::sim::SceneContext& c) { \
         return std::unique_ptr<::speckle::sim::SimEffect>(std::make_unique<Class>(fields, c));              \
       }});

}  // namespace speckle::sim
