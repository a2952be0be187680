#pragma once
// samples.h5: a calibration's paired samples and their camera perturbations,
// so a refit needs no detection. Older schema versions are read with the
// columns they lack at their defaults.
#include <filesystem>
#include <vector>

#include "lab/fit/depth_fit.h"

namespace speckle {

struct CachedSamples {
  std::vector<PairedSample> samples;
  DepthPerturbations perturbations;  // in_floor: all of them before schema 5
};
void WriteSamples(const std::filesystem::path& path, const std::vector<PairedSample>& samples,
                  const DepthPerturbations& perturbations);
CachedSamples ReadSamples(const std::filesystem::path& path);  // throws InputError

}  // namespace speckle
