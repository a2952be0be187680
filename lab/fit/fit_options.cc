#include "lab/fit/fit_options.h"

#include <cmath>

#include "schemas/option_check.h"

namespace speckle {

bool DepthFitOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .Require(std::isfinite(huber_raw) && huber_raw >= 0, "huber_raw", "finite and >= 0 (0: no Huber loss)")
      .Require(folds >= 0, "folds", ">= 0 (0: no cross-validation)")
      .Require(max_iterations >= 1, "max_iterations", ">= 1")
      .Require(max_refit_samples >= 1, "max_refit_samples", ">= 1")
      .Require(std::isfinite(camera_freedom_sigma) && camera_freedom_sigma >= 0, "camera_freedom_sigma",
               "finite and >= 0 (0: the cameras held)")
      .Require(sparse_from_parameters >= 1, "sparse_from_parameters", ">= 1")
      .valid();
}

}  // namespace speckle
