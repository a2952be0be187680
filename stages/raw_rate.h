#pragma once
// Stage 6: how fast each board point's raw value changes (or the raw value
// at its pixel: RawRateOptions::at_fixed_pixel), from the same board point
// in the neighbouring depth frames. A depth image exposed at another
// instant than the colour image reads every raw value moved by this rate
// times the delay (the capture_time_offset effect). Measured in the depth
// frames rather than from the colour poses: a pose found by detection and
// the next found by tracking differ by up to a degree and a centimetre,
// which 33 ms apart reads as 0.3 m/s.
#include <string>
#include <vector>

#include "stages/records.h"

namespace speckle {

struct RawRateOptions {
  // Neighbouring frames at most this far apart (a dropped frame or two, not
  // another pose much later).
  double max_gap_s = 0.1;
  // A frame's rates are a plane over the depth image fitted to its points'
  // raw differences, which are noisy one by one; with fewer points in common
  // with its neighbours they stay 0.
  int min_points = 10;
  // Which change a sample's delay offset is. The pairing places board points
  // by the depth outline (at the depth exposure) and takes their depth from
  // the colour pose, so its samples are off by each board point's own change
  // (false). The joint calibration takes a sample's depth where its pixel's
  // ray meets the colour-time board plane, so its samples are off by the
  // change at that fixed pixel: the point's change less the raw gradient
  // along its path over the image (true). A tilted board sliding along its
  // plane changes every point's raw value and no pixel's.
  bool at_fixed_pixel = false;
  // False, naming the first broken rule's field in *why (schemas/option_check.h).
  bool IsValid(std::string* why) const;
};

// Returns the samples with raw_rate set, each frame's from two other frames
// of its run, or in a run of two from the pair (see stages/rate_neighbours.h).
std::vector<PairedSample> AssignRawRates(const RawRateOptions& options, std::vector<PairedSample> samples);

}  // namespace speckle
