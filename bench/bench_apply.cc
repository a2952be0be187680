// VGA raw depth -> organized point cloud, frames per second on one core:
//   Corrector   the apply library (folded per-pixel tables, no resampling)
//   Naive       the generic model evaluated at every pixel, ray undistorted on the way
//   OpenCvRemap the usual way: raw -> depth by the base form's lookup table,
//               cv::remap onto an undistorted image, pinhole unprojection
//   MemoryBound the bytes the corrector must move (raw, rays, two table
//               planes in, xyz out: 30 B a pixel, 9.2 MB a frame) streamed
//               with no arithmetic: its ceiling
// /1 and /32: frames in flight; /32 streams inputs and outputs through main
// memory. Run it on one core: taskset -c 1 build/bench/bench_apply
// Usage: bench_apply [benchmark flags] [CALIBRATION_VERSION_DIR]
// (default: run-pipeline on a copy of the golden test session).
#include <benchmark/benchmark.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "apply/depth_corrector.h"
#include "model/depth_model.h"

namespace speckle::apply {
namespace {

namespace fs = std::filesystem;
constexpr int kWidth = 640, kHeight = 480, kPixels = kWidth * kHeight;

DepthCalibration* g_calibration = nullptr;

// A room-like scene: a floor ramp from 1.2 to 4 m with a box at 0.9 m and
// a few patches of no reading.
std::vector<std::uint16_t> SceneRaw(const DepthCalibration& c) {
  const model::DepthModel& m = *c.model;
  std::vector<std::uint16_t> raw(kPixels);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      double z = 4.0 - 2.8 * v / kHeight;
      if (u > 200 && u < 380 && v > 150 && v < 330) z = 0.9;
      const double r = model::RawFromDepth(m.Definition().form, m.Base().data(), z);
      raw[v * kWidth + u] = ((u / 40 + v / 40) % 13 == 0) ? 2047 : static_cast<std::uint16_t>(std::lround(r));
    }
  }
  return raw;
}

void Frames(benchmark::State& state) {
  state.SetItemsProcessed(state.iterations());
  state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

// Arg: frames in flight. 1 keeps a frame's input and output in cache; 32
// (about 100 MB of raw frames and clouds) makes them come from and go to
// main memory, as a stream of new frames does.
void Corrector(benchmark::State& state) {
  const DepthCorrector corrector(*g_calibration);
  const std::vector<std::vector<std::uint16_t>> raw(state.range(0), SceneRaw(*g_calibration));
  std::vector<std::vector<float>> xyz(state.range(0), std::vector<float>(3 * kPixels));
  std::size_t frame = 0;
  for (auto _ : state) {
    corrector.PointCloud(raw[frame], 0, xyz[frame]);
    benchmark::DoNotOptimize(xyz[frame].data());
    frame = (frame + 1) % raw.size();
  }
  state.counters["knots"] = corrector.Summary().knots;
  Frames(state);
}

// The cloud and each point's colour from a VGA colour frame.
void CorrectorWithColour(benchmark::State& state) {
  const DepthCorrector corrector(*g_calibration);
  const auto raw = SceneRaw(*g_calibration);
  const std::vector<std::uint8_t> rgb(3 * g_calibration->colour.width * g_calibration->colour.height, 128);
  std::vector<float> xyz(3 * kPixels);
  std::vector<std::uint8_t> colours(3 * kPixels);
  for (auto _ : state) {
    corrector.PointCloud(raw, 0, xyz);
    corrector.RegisterColour(xyz, rgb, colours);
    benchmark::DoNotOptimize(colours.data());
  }
  Frames(state);
}

void Naive(benchmark::State& state) {
  const auto raw = SceneRaw(*g_calibration);
  std::vector<float> xyz(3 * kPixels);
  for (auto _ : state) {
    NaivePointCloud(*g_calibration, {}, raw, 0, xyz);
    benchmark::DoNotOptimize(xyz.data());
  }
  Frames(state);
}

void OpenCvRemap(benchmark::State& state) {
  const DepthCalibration& c = *g_calibration;
  const auto raw = SceneRaw(c);
  std::vector<float> depth_of_raw(2048, 0.0f);  // the driver's lookup: base form only
  for (int r = 1; r < 2047; ++r)
    depth_of_raw[r] =
        static_cast<float>(model::DepthFromRaw(c.model->Definition().form, c.model->Base().data(), double(r)));
  const cv::Matx33d k(c.depth.fx, 0, c.depth.cx, 0, c.depth.fy, c.depth.cy, 0, 0, 1);
  cv::Mat map1, map2;
  cv::initUndistortRectifyMap(k, cv::Mat(c.depth.distortion), cv::Mat(), k, {kWidth, kHeight}, CV_16SC2, map1, map2);
  cv::Mat depth(kHeight, kWidth, CV_32F), rectified;
  std::vector<float> xyz(3 * kPixels);
  for (auto _ : state) {
    for (int p = 0; p < kPixels; ++p) depth.ptr<float>()[p] = depth_of_raw[raw[p] & 2047];
    cv::remap(depth, rectified, map1, map2, cv::INTER_LINEAR);
    for (int v = 0; v < kHeight; ++v) {
      const float* z = rectified.ptr<float>(v);
      for (int u = 0; u < kWidth; ++u) {
        float* out = &xyz[3 * (v * kWidth + u)];
        out[0] = z[u] * static_cast<float>((u - c.depth.cx) / c.depth.fx);
        out[1] = z[u] * static_cast<float>((v - c.depth.cy) / c.depth.fy);
        out[2] = z[u];
      }
    }
    benchmark::DoNotOptimize(xyz.data());
  }
  Frames(state);
}

// Arg: frames in flight, as for Corrector; with 32 every byte comes from
// or goes to main memory, the bound of a stream of distinct frames.
void MemoryBound(benchmark::State& state) {
  // Per pixel: 2 B raw, 8 B ray, 8 B of two table planes in; 12 B out.
  struct Buffers {
    std::vector<std::uint16_t> raw;
    std::vector<float> ray_x, ray_y, plane0, plane1, xyz;
  };
  std::vector<Buffers> frames(
      state.range(0),
      Buffers{SceneRaw(*g_calibration), std::vector<float>(kPixels, 0.1f), std::vector<float>(kPixels, 0.2f),
              std::vector<float>(kPixels, 1.0f), std::vector<float>(kPixels, 2.0f), std::vector<float>(3 * kPixels)});
  std::size_t frame = 0;
  for (auto _ : state) {
    Buffers& b = frames[frame];
    const std::uint16_t* __restrict raw = b.raw.data();
    const float* __restrict ray_x = b.ray_x.data(), * __restrict ray_y = b.ray_y.data();
    const float* __restrict plane0 = b.plane0.data(), * __restrict plane1 = b.plane1.data();
    float* __restrict xyz = b.xyz.data();
    for (int p = 0; p < kPixels; ++p) {
      const float h = plane0[p] + plane1[p] + raw[p];
      xyz[3 * p] = h * ray_x[p];
      xyz[3 * p + 1] = h * ray_y[p];
      xyz[3 * p + 2] = h;
    }
    benchmark::DoNotOptimize(xyz);
    frame = (frame + 1) % frames.size();
  }
  state.counters["MB_per_frame"] = 30.0 * kPixels / 1e6;
  state.counters["GB_per_s"] =
      benchmark::Counter(30.0 * kPixels * static_cast<double>(state.iterations()) / 1e9, benchmark::Counter::kIsRate);
  Frames(state);
}

}  // namespace
}  // namespace speckle::apply

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  benchmark::Initialize(&argc, argv);
  fs::path version;
  if (argc > 1) {
    version = argv[1];
  } else {
    const fs::path scratch = fs::temp_directory_path() / "speckle-bench-apply";
    fs::remove_all(scratch);
    fs::create_directories(scratch);
    fs::copy(fs::path(SPECKLE_SOURCE_DIR) / "tests" / "golden" / "session", scratch / "s", fs::copy_options::recursive);
    const std::string command =
        std::string(SPECKLE_BIN_DIR) + "/run-pipeline " + (scratch / "s").string() + " >/dev/null 2>&1";
    if (std::system(command.c_str()) != 0) {
      std::cerr << "bench_apply: " << command << " failed\n";
      return 1;
    }
    version = scratch / "s" / "calibrations" / "v0001";
  }
  speckle::apply::DepthCalibration calibration = speckle::apply::LoadDepthCalibration(version);
  speckle::apply::g_calibration = &calibration;
  benchmark::RegisterBenchmark("MemoryBound", speckle::apply::MemoryBound)->Arg(1)->Arg(32);
  benchmark::RegisterBenchmark("Corrector", speckle::apply::Corrector)->Arg(1)->Arg(32);
  benchmark::RegisterBenchmark("CorrectorWithColour", speckle::apply::CorrectorWithColour);
  benchmark::RegisterBenchmark("OpenCvRemap", speckle::apply::OpenCvRemap);
  benchmark::RegisterBenchmark("Naive", speckle::apply::Naive)->Iterations(3);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
}
