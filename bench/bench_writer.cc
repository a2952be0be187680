// Recording writer alone: VGA colour + raw depth pairs per second through the
// same pipeline record-session uses (serial read, parallel compression,
// in-order write), per codec, with "none" as the same-run baseline.
// Frames are held in memory: real Kinect frames (Herrera's sample set, colour
// resized to VGA) and simulated ones.
//   build/bench/bench_writer [--benchmark_filter=...]
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#include <cstdlib>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "recorder/session_recorder.h"
#include "recorder/sources/pnm.h"
#include "simulator/session_simulator.h"

namespace speckle {
namespace {

namespace fs = std::filesystem;

std::vector<FramePair> LoadRealFrames() {
  std::vector<FramePair> frames;
  const fs::path dir = fs::path(SPECKLE_SHARED_DATA) / "herrera_kinect_calib";
  for (int i = 0; i < 10; ++i) {
    char name[16];
    std::snprintf(name, sizeof name, "%04d", i);
    FramePair f;
    cv::Mat bgr = cv::imread((dir / (std::string(name) + "-c1.jpg")).string());
    cv::resize(bgr, bgr, cv::Size(640, 480), 0, 0, cv::INTER_AREA);
    cv::cvtColor(bgr, f.colour.image, cv::COLOR_BGR2RGB);
    f.depth.image = ReadPgm16(dir / (std::string(name) + "-d.pgm"), ByteOrder::kBigEndian, {{640, 480}, {2048}});
    frames.push_back(f);
  }
  return frames;
}

std::vector<FramePair> LoadSimulatedFrames() {
  const sim::SessionSimulator simulator(sim::Scenario{});
  std::vector<FramePair> frames;
  for (int i = 0; i < 10; ++i) {
    const auto& spec = simulator.Frames(sim::SimRecording::kDepthboard).at(static_cast<std::size_t>(3 * i));
    sim::SimFrame f = simulator.Render(sim::SimRecording::kDepthboard, spec);
    FramePair pair;
    pair.colour.image = f.colour_rgb;
    pair.depth.image = f.raw_depth;
    frames.push_back(pair);
  }
  return frames;
}

class MemorySource : public FrameSource {
 public:
  MemorySource(const std::vector<FramePair>& frames, int count) : frames_(frames), count_(count) {}
  std::int64_t expected_frames() const override { return count_; }
  std::optional<FramePair> Next() override {
    if (next_ >= count_) return std::nullopt;
    FramePair f = frames_[next_ % frames_.size()];
    f.source_number = next_++;
    return f;
  }

 private:
  const std::vector<FramePair>& frames_;
  int count_;
  int next_ = 0;
};

// range(0): codec; range(1): 0 = real Kinect frames, 1 = simulated frames.
void BM_WriteVgaPairs(benchmark::State& state) {
  static const std::vector<FramePair> real = LoadRealFrames();
  static const std::vector<FramePair> simulated = LoadSimulatedFrames();
  const std::vector<FramePair>& frames = state.range(1) == 0 ? real : simulated;
  const auto codec = static_cast<Codec>(state.range(0));
  const fs::path dir = fs::temp_directory_path() / "speckle-bench-writer";
  fs::remove_all(dir);
  fs::create_directories(dir);
  RecordingHeader header;
  header.purpose = RecordingPurpose::kDepthboard;
  header.source = "bench";
  header.colour_size = cv::Size(640, 480);
  header.depth_size = cv::Size(640, 480);
  constexpr int kPairs = 300;
  std::int64_t bytes = 0, run = 0;
  const int threads = std::getenv("BENCH_THREADS") ? std::atoi(std::getenv("BENCH_THREADS")) : 2;
  const int in_flight = std::getenv("BENCH_IN_FLIGHT") ? std::atoi(std::getenv("BENCH_IN_FLIGHT")) : 8;
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  for (auto _ : state) {
    const fs::path file = dir / ("r" + std::to_string(run++) + ".h5");
    MemorySource source(frames, kPairs);
    RecordingWriter writer(file, header, {codec, 1, std::chrono::milliseconds(500)});
    WriteRecording(source, writer, "bench", in_flight);
    state.PauseTiming();
    bytes += static_cast<std::int64_t>(fs::file_size(file));
    fs::remove(file);
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * kPairs);
  state.counters["MB_per_pair"] = double(bytes) / (state.iterations() * kPairs) / 1e6;
  state.SetLabel(ToString(codec) + (state.range(1) == 0 ? " real-frames" : " simulated-frames"));
  fs::remove_all(dir);
}
BENCHMARK(BM_WriteVgaPairs)
    ->ArgsProduct({{static_cast<int>(Codec::kNone), static_cast<int>(Codec::kSzip), static_cast<int>(Codec::kDeflate),
                    static_cast<int>(Codec::kLz4)},
                   {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

}  // namespace
}  // namespace speckle

BENCHMARK_MAIN();
