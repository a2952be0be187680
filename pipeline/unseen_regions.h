#pragma once
// Where a refit moves the depth in image regions no board pose reached: the
// new model is extrapolated there (issue 47: Herrera's pattern refit moved a
// flat scene at 0.50 m by up to 89 mm in the lower-left corner, unsaid).
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "apply/depth_calibration.h"
#include "lab/diagnosis/diagnosis.h"
#include "lab/fit/depth_uncertainty.h"

namespace speckle {

struct UnseenChange {
  double unseen_share = 0;  // of the image's coverage cells, those no pose reached
  double depth_m = 0;       // the flat scene where the depth moved most
  double moved_mm = 0;      // |new - parent| there, less its median where poses reached, at pixel (u, v)
  int u = 0, v = 0;
  double sigma_mm = 0;  // the new model's sigma at that depth, image centre
  std::string region;   // "the lower-left corner", "the top edge", ...
  bool BeyondSigma() const { return moved_mm > sigma_mm; }
};

// Both calibrations applied to flat scenes at 0.5, 1, 2 and 3 m (a constant
// raw value at the parent's depth for it) over the cells `coverage` says no
// pose reached, less the median change where poses reached; nothing when
// every cell was reached or none has a depth under both.
std::optional<UnseenChange> LargestUnseenChange(const apply::DepthCalibration& parent,
                                                const apply::DepthCalibration& refit, const Coverage& coverage,
                                                const std::vector<DepthSigma>& sigma);

nlohmann::json ToJson(const UnseenChange& c);
// The warning when the depth moved beyond sigma there (else empty), and the
// refit summary's line: within sigma, or that warning.
std::string UnseenChangeWarning(const UnseenChange& c, const std::string& parent_name);
std::string UnseenChangeLine(const UnseenChange& c, const std::string& parent_name);

}  // namespace speckle
