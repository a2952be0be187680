// Simulator speed: VGA colour + depth frames rendered per second, and a whole
// 100-frame session recorded end to end (render + compress + write), with 1
// thread and 2 threads in the same run.
//   build/bench/bench_simulator
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <filesystem>

#include "recorder/session_recorder.h"
#include "recorder/sources/sim_source.h"
#include "simulator/session_simulator.h"

namespace speckle {
namespace {

void BM_RenderDepthboardFrame(benchmark::State& state) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
  static const sim::SessionSimulator simulator((sim::Scenario()));
  const auto& frames = simulator.Frames(sim::SimRecording::kDepthboard);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(simulator.Render(sim::SimRecording::kDepthboard, frames[i++ % frames.size()]));
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(std::to_string(state.range(0)) + " thread(s)");
}
BENCHMARK(BM_RenderDepthboardFrame)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Record100FrameSession(benchmark::State& state) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
  sim::Scenario scenario;
  scenario.depthboard.poses = 25;
  scenario.depthboard.frames_per_pose = 3;
  scenario.planar.snapshots = 25;
  scenario.planar.frames_per_snapshot = 1;
  scenario.ir_chessboard.poses = 0;  // 75 + 25 = 100 colour + depth frames
  const auto dir = std::filesystem::temp_directory_path() / "speckle-bench-sim";
  int run = 0;
  for (auto _ : state) {
    std::filesystem::remove_all(dir);
    const auto summary = RecordSession(PlanSimulatedSession(scenario, {}), dir / std::to_string(run++));
    benchmark::DoNotOptimize(summary);
  }
  std::filesystem::remove_all(dir);
  state.SetItemsProcessed(state.iterations() * 100);
  state.SetLabel(std::to_string(state.range(0)) + " thread(s)");
}
BENCHMARK(BM_Record100FrameSession)->Arg(1)->Arg(2)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace
}  // namespace speckle

BENCHMARK_MAIN();
