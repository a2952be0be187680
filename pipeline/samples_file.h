#pragma once
// samples.h5: a calibration's paired samples and their camera perturbations,
// so a refit needs no detection. Older schema versions are read with the
// columns they lack at their defaults.
#include <filesystem>
#include <vector>

#include "lab/fit/depth_fit.h"
#include "lab/joint/joint_calibration.h"

namespace speckle {

struct CachedSamples {
  std::vector<PairedSample> samples;
  DepthPerturbations perturbations;  // in_floor: all of them before schema 5
  // Every paired board frame's colour corners, outline and start pose, for
  // a refit that re-runs the joint calibration (schema 6; empty before, or
  // when the run's cameras were not the joint calibration's).
  std::vector<joint::BoardFrame> board_frames;
};
void WriteSamples(const std::filesystem::path& path, const std::vector<PairedSample>& samples,
                  const DepthPerturbations& perturbations, const std::vector<joint::BoardFrame>& board_frames = {});
CachedSamples ReadSamples(const std::filesystem::path& path);  // throws InputError

}  // namespace speckle
