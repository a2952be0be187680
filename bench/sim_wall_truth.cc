// The simulator's true wall mask of every planar frame of a simulated
// session, for benchmarks that judge wall segmentation (bench/room_benchmark.py).
// The session's own /truth scenario_json (concrete: a randomized scenario is
// stored as drawn) rebuilds the simulator, whose ray caster says which
// surface each depth pixel sees.
//
//   sim_wall_truth SESSION_DIR OUT_DIR
//
// writes OUT_DIR/NNNNNN.png per planar frame: 255 where the ray hits the wall
// (sim::Surface::kTarget), 0 on floor, ceiling, clutter or nothing. Pixels the
// sensor gives no reading (raw 2047) are the caller's to leave out. Exit
// codes: 0 done, 2 usage, 3 bad input (no planar recording, no truth).
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "recorder/recording_reader.h"
#include "schemas/errors.h"
#include "simulator/scenario.h"
#include "simulator/scene_renderer.h"
#include "simulator/session_simulator.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: sim_wall_truth SESSION_DIR OUT_DIR\n";
    return 2;
  }
  try {
    const fs::path planar = fs::path(argv[1]) / "planar.h5";
    if (!fs::exists(planar)) throw speckle::InputError(planar.string() + ": no planar recording in the session");
    const speckle::RecordingReader reader(planar);
    const std::string& text = reader.header().scenario_json;
    if (text.empty()) throw speckle::InputError(planar.string() + ": /truth scenario_json missing (not simulated)");
    const auto scenario = speckle::sim::ScenarioFromJson(nlohmann::json::parse(text), planar.string() + ": /truth");
    const speckle::sim::SessionSimulator simulator(scenario);
    const auto& frames = simulator.Frames(speckle::sim::SimRecording::kPlanar);
    if (static_cast<std::int64_t>(frames.size()) != reader.frame_count()) {
      throw speckle::InputError(planar.string() + ": " + std::to_string(reader.frame_count()) +
                                " frames, the scenario simulates " + std::to_string(frames.size()));
    }
    fs::create_directories(argv[2]);
    for (const auto& spec : frames) {
      const cv::Mat wall = simulator.TrueDepth(spec).surface == static_cast<int>(speckle::sim::Surface::kTarget);
      char name[32];
      std::snprintf(name, sizeof name, "%06d.png", spec.index);
      cv::imwrite((fs::path(argv[2]) / name).string(), wall);
    }
    std::cout << frames.size() << " true wall masks in " << argv[2] << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 3;
  }
}
