#pragma once
// How a calibration's depth sigma varies over the image. report.json states
// it at the image centre only (lab/fit/depth_uncertainty.h); a model with
// terms over the image (a per-pixel pattern, a billow, an offset across it)
// is looser at the edges than there. The shape is the model's parameter
// covariance (calibration.json's model.covariance) moved through its depth
// at each pixel, relative to the centre's: compare scales the report's row
// by it, so the centre keeps the report's sigma.
#include <vector>

#include "apply/depth_calibration.h"

namespace speckle {

struct ModelSigmaShape {
  int width = 0, height = 0, step_px = 0, cells_u = 0, cells_v = 0;
  std::vector<double> factor;  // per cell node, row-major; empty: 1 everywhere
  // Sigma at pixel (u, v) over sigma at the centre, bilinear between the nodes.
  double At(double u, double v) const;
};

// At raw value `raw` (the session's units), on nodes every `step_px` pixels
// and at the image's last row and column. Empty when `covariance` (row-major,
// the model's flat parameters squared) does not match the model, or the
// centre's sigma is 0.
ModelSigmaShape ModelSigmaShapeAt(const apply::DepthCalibration& calibration, const std::vector<double>& covariance,
                                  double raw, int step_px = 40);

}  // namespace speckle
