#include "recorder/sources/sim_source.h"

#include <chrono>
#include <thread>

#include "simulator/session_simulator.h"

namespace speckle {
namespace {

// Simulated clocks: host time from a fixed epoch so sessions are
// reproducible; the device counter runs at 60 MHz and wraps at 32 bits.
constexpr std::int64_t kSimEpochNs = 1'800'000'000LL * 1'000'000'000LL;
constexpr double kDeviceTicksPerSecond = 60e6;

std::vector<double> RowMajor(const Eigen::Isometry3d& pose) {
  std::vector<double> values(16);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) values[r * 4 + c] = pose.matrix()(r, c);
  return values;
}

class SimSource : public FrameSource {
 public:
  SimSource(std::shared_ptr<const sim::SessionSimulator> simulator, sim::SimRecording which, bool realtime)
      : simulator_(std::move(simulator)), which_(which), realtime_(realtime) {}
  std::int64_t expected_frames() const override { return static_cast<std::int64_t>(simulator_->Frames(which_).size()); }
  std::optional<FramePair> Next() override {
    const auto& specs = simulator_->Frames(which_);
    if (next_ >= specs.size() || StopRequested()) return std::nullopt;
    if (realtime_) {
      const auto due = start_ + std::chrono::duration<double>(next_ / simulator_->scenario().frame_rate_hz);
      std::this_thread::sleep_until(std::chrono::time_point_cast<std::chrono::steady_clock::duration>(due));
    }
    const sim::SimFrameSpec& spec = specs[next_++];
    sim::SimFrame rendered = simulator_->Render(which_, spec);
    FramePair pair;
    pair.source_number = spec.index;
    const double time_s = spec.context.time_s;
    const auto host_ns = kSimEpochNs + static_cast<std::int64_t>(time_s * 1e9);
    const auto ticks = static_cast<std::uint64_t>(time_s * kDeviceTicksPerSecond) & 0xffffffffULL;
    const auto stamp = [&](StreamFrame& frame, const cv::Mat& image) {
      frame.image = image;
      frame.device_timestamp = ticks;
      frame.host_time_ns = host_ns;
    };
    stamp(pair.colour, rendered.colour_rgb);
    stamp(pair.depth, rendered.raw_depth);
    stamp(pair.ir, rendered.ir);
    pair.series["truth/ir_from_target"] = RowMajor(spec.colour_target.ir_from_target);
    pair.series["truth/ir_from_target_at_depth"] = RowMajor(spec.depth_target.ir_from_target);
    pair.series["truth/time_s"] = std::vector<double>{time_s};
    pair.series["truth/pose_index"] = std::vector<double>{static_cast<double>(spec.context.pose)};
    return pair;
  }

 private:
  std::shared_ptr<const sim::SessionSimulator> simulator_;
  sim::SimRecording which_;
  bool realtime_;
  std::size_t next_ = 0;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace

SessionPlan PlanSimulatedSession(const sim::Scenario& scenario, const SimCaptureOptions& options) {
  auto simulator = std::make_shared<const sim::SessionSimulator>(scenario);
  SessionPlan plan;
  plan.streaming = true;
  SessionManifest& m = plan.manifest;
  m.sensor = {"kinect_v1", scenario.label, "sim-seed-" + std::to_string(scenario.seed)};
  m.driver = "simulator";
  m.depth_units = scenario.depth.millimetre ? DepthUnits::kMillimetre : DepthUnits::kRaw11Bit;
  m.optics = scenario.optics;
  m.rig = RigInfo{scenario.rig.squares_x, scenario.rig.squares_y, scenario.rig.square_size_m,
                  BoardOutline::kChessboardEdge, "simulated board proud of a wall"};
  m.notes = "simulated session; ground truth under /truth in each recording";
  const std::string scenario_json = sim::ToJson(scenario).dump();
  const auto add = [&](sim::SimRecording which, RecordingPurpose purpose) {
    if (simulator->Frames(which).empty()) return;
    PlannedRecording r;
    r.file = ToString(purpose) + ".h5";
    r.header.purpose = purpose;
    r.header.source = "sim";
    if (which == sim::SimRecording::kIrChessboard) {
      r.header.ir_size = simulator->optics().ir.size;
    } else {
      r.header.colour_size = simulator->optics().colour.size;
      r.header.depth_size = simulator->optics().ir.size;
    }
    r.header.depth_units = m.depth_units;
    r.header.scenario_json = scenario_json;
    r.header.series = {
        {"truth/ir_from_target", {4, 4}, "target to IR camera (metres, row-major) when colour/IR was exposed"},
        {"truth/ir_from_target_at_depth", {4, 4}, "target to IR camera (metres, row-major) when depth was exposed"},
        {"truth/time_s", {}, "seconds since the session started"},
        {"truth/pose_index", {}, "still pose (board) or snapshot (wall) the frame belongs to"}};
    r.source = std::make_unique<SimSource>(simulator, which, options.realtime);
    plan.recordings.push_back(std::move(r));
  };
  add(sim::SimRecording::kDepthboard, RecordingPurpose::kDepthboard);
  add(sim::SimRecording::kPlanar, RecordingPurpose::kPlanar);
  add(sim::SimRecording::kIrChessboard, RecordingPurpose::kIrChessboard);
  return plan;
}

}  // namespace speckle
