#include <cmath>

#include "lab/diagnosis/diagnosis.h"
#include "schemas/option_check.h"

namespace speckle {

namespace {
bool Share(double v) { return std::isfinite(v) && v >= 0 && v <= 1; }
bool Probability(double v) { return std::isfinite(v) && v > 0 && v <= 1; }
}  // namespace

bool DiagnosisOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .Require(std::isfinite(complete_ratio) && complete_ratio >= 1, "complete_ratio", "finite and >= 1")
      .Require(Share(min_reduction), "min_reduction", "a share from 0 to 1")
      .Require(Probability(max_p_value), "max_p_value", "a p value in (0, 1]")
      .Require(Share(strong_reduction) && strong_reduction >= min_reduction, "strong_reduction",
               "a share from min_reduction to 1")
      .Require(Probability(strong_max_p_value), "strong_max_p_value", "a p value in (0, 1]")
      .Require(Probability(covariate_max_p_value), "covariate_max_p_value", "a p value in (0, 1]")
      .Require(pose_profile_bins >= 2, "pose_profile_bins", ">= 2")
      .Require(Share(parsimony_share), "parsimony_share", "a share from 0 to 1")
      .Require(bins >= 2, "bins", ">= 2")
      .Require(max_candidate_samples >= 1, "max_candidate_samples", ">= 1")
      .Require(folds >= 2, "folds", ">= 2 (the candidates are judged held out)")
      .Require(std::isfinite(max_consecutive_gap_s) && max_consecutive_gap_s > 0, "max_consecutive_gap_s", "> 0")
      .Require(min_neighbour_corner_px >= 0 && max_neighbour_corner_px > min_neighbour_corner_px,
               "max_neighbour_corner_px", "> min_neighbour_corner_px >= 0")
      .Require(std::isfinite(camera_freedom_sigma) && camera_freedom_sigma >= 0, "camera_freedom_sigma",
               "finite and >= 0")
      .Require(std::isfinite(max_joint_sigma_ratio) && max_joint_sigma_ratio >= 1, "max_joint_sigma_ratio",
               "finite and >= 1")
      .Require(std::isfinite(coverage_cell_px) && coverage_cell_px >= 1, "coverage_cell_px", ">= 1")
      .Require(image_width_px >= 1 && image_height_px >= 1, "image_width_px", ">= 1, and so image_height_px")
      .Require(min_poses_per_cell >= 1, "min_poses_per_cell", ">= 1")
      .Require(Share(under_determined_share), "under_determined_share", "a share from 0 to 1")
      .valid();
}

bool DiagnosisOptions::PassesPoseTest(double reduction, double p_value) const {
  return (reduction >= min_reduction && p_value <= max_p_value) ||
         (reduction >= strong_reduction && p_value <= strong_max_p_value);
}

}  // namespace speckle
