// Whole-pipeline speed: depthboard frame pairs per second on a 300-frame
// simulated session (100 still poses x 3 frames, plus walls and IR views),
// with 1 thread and 2 threads, and the share of stage time per stage.
//   build/bench/bench_pipeline
#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <filesystem>
#include <iostream>

#include "pipeline/calibration_graph.h"
#include "recorder/session_recorder.h"
#include "recorder/sources/sim_source.h"

int main() {
  using namespace speckle;
  spdlog::set_level(spdlog::level::warn);
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "speckle-bench-pipeline";
  fs::remove_all(dir);
  sim::Scenario scenario;
  scenario.depthboard.poses = 100;
  scenario.depthboard.frames_per_pose = 3;
  scenario.planar.snapshots = 12;
  scenario.ir_chessboard.poses = 12;
  std::cerr << "recording a 300-frame session...\n";
  RecordSession(PlanSimulatedSession(scenario, {}), dir / "s");
  double one_thread = 0;
  for (int threads : {1, 2}) {
    PipelineOptions options;
    options.threads = threads;
    const PipelineResult r = RunCalibrationGraph(dir / "s", options);
    const double rate = r.board_frames / r.wall_seconds;
    if (threads == 1) one_thread = rate;
    std::cout << fmt::format(
        "{} thread(s): {:.1f} s for {} depthboard frames ({} paired) + {} other frames: "
        "{:.1f} frame pairs/s{}\n",
        threads, r.wall_seconds, r.board_frames, r.paired_frames, r.frames.size() - r.board_frames, rate,
        threads == 1 ? "" : fmt::format(" ({:.2f}x one thread)", rate / one_thread));
    double total = 0;
    for (const auto& t : r.timings) total += t.seconds;
    for (const auto& t : r.timings) {
      std::cout << fmt::format("    {:<24} {:5.1f} %  ({:.2f} s over {} calls)\n", t.stage, 100 * t.seconds / total,
                               t.seconds, t.calls);
    }
  }
  fs::remove_all(dir);
}
