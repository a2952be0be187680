// The HDF5 artifacts of a calibration version, mutated through the HDF5 API
// (fuzz/h5_mutation.h): the first byte chooses samples.h5 (read as refit
// reads it) or undistortion_grid.h5 (read, then applied as apply-calibration
// applies it).
#include <filesystem>
#include <fstream>

#include "apply/undistortion_grid_file.h"
#include "fuzz/fuzz_input.h"
#include "fuzz/h5_mutation.h"
#include "pipeline/samples_file.h"

using namespace speckle;

namespace {

std::string Slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

std::string TemplateSamples() {
  const std::filesystem::path path = fuzz::Scratch() / "samples_template.h5";
  std::filesystem::remove(path);
  std::vector<PairedSample> samples(6);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    samples[i].frame = static_cast<int>(i), samples[i].pose = static_cast<int>(i / 2);
    samples[i].raw = 700 + 10.0 * i, samples[i].depth_m = 1 + 0.1 * i;
  }
  WriteSamples(path, samples, DepthPerturbations{{std::vector<double>(samples.size(), 1.0)}, 1});
  return Slurp(path);
}

std::string TemplateGrid() {
  const std::filesystem::path path = fuzz::Scratch() / "grid_template.h5";
  std::filesystem::remove(path);
  UndistortionGrid g;
  g.x_min = g.y_min = -0.5, g.x_max = g.y_max = 0.5, g.nx = 3, g.ny = 2;
  g.raw_nodes = {600, 800, 1000};
  g.correction.assign(18, 1.5f), g.std_error.assign(18, 0.1f), g.supported.assign(18, 1);
  WriteGrid(path, g);
  return Slurp(path);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const std::string samples = TemplateSamples(), grid = TemplateGrid();
  const bool is_grid = data[0] % 2;
  const std::filesystem::path path = fuzz::Scratch() / (is_grid ? "undistortion_grid.h5" : "samples.h5");
  fuzz::WriteBytes(path, is_grid ? grid : samples);
  fuzz::FuzzBytes in(data + 1, size - 1);
  if (!fuzz::MutateH5(path.string(), in)) return 0;
  fuzz::ExpectOnlyInputErrors([&] {
    if (!is_grid) {
      (void)ReadSamples(path);
      return;
    }
    const UndistortionGrid g = ReadGrid(path);
    for (double raw : {0.0, 650.0, 2047.0, -1e9, 1e9})
      for (double x : {-1.0, 0.0, 0.3})
        if (!std::isfinite(g.Apply(raw, x, x))) throw std::logic_error("a sound grid gave a non-finite raw value");
  });
  return 0;
}
