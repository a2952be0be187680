#pragma once
// A camera the session gave with standard deviations (session.json
// cameras.colour / cameras.depth stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3) enters
// the joint calibration as a Gaussian prior rather than as exact: each
// intrinsic is drawn to its given value by its sigma, and the data move it
// as far as they outweigh that (issue 46: "priors with their sigma"). A term
// given with sigma 0 is held at its value.
#include <ceres/problem.h>

#include <string>
#include <vector>

#include "lab/joint/joint_problem.h"

namespace speckle::joint {

// Adds the priors of in.cameras.colour_prior and depth_prior to `problem`
// (each camera's whose blocks are free), as kinds.prior, counted as
// independent in the covariance; holds their terms of sigma 0 and names
// them in `held`.
void AddCameraPriors(const JointInput& in, Blocks& b, ceres::Problem& problem, Kinds& kinds,
                     std::vector<std::string>* held);

}  // namespace speckle::joint
