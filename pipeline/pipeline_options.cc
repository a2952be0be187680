#include "pipeline/pipeline_options.h"

#include <cmath>

#include "schemas/option_check.h"

namespace speckle {

bool PipelineOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .Require(batch_frames >= 1, "batch_frames", ">= 1")
      .Require(std::isfinite(nominal_prediction_px) && nominal_prediction_px > 0, "nominal_prediction_px", "> 0")
      .Require(still_frames_averaged >= 1 && still_frames_averaged <= 64, "still_frames_averaged", "from 1 (off) to 64")
      .Require(std::isfinite(still_pose_motion_px) && still_pose_motion_px >= 0, "still_pose_motion_px", ">= 0")
      .Require(std::isfinite(max_velocity_gap_s) && max_velocity_gap_s > 0, "max_velocity_gap_s", "> 0")
      .Require(threads >= 0, "threads", ">= 0 (0: all cores)")
      .Require(held_raw_frames >= 0, "held_raw_frames", ">= 0")
      .Require(!refit_tool.empty(), "refit_tool", "a command name")
      .Part("detection", detection)
      .Part("tracking", tracking)
      .Part("intrinsics", intrinsics)
      .Part("quad", quad)
      .Part("still_average", still_average)
      .Part("board_region", board_region)
      .Part("joint_plane", joint_plane)
      .Part("extrinsics", extrinsics)
      .Part("pairing", pairing)
      .Part("raw_rate", raw_rate)
      .Part("planar", planar)
      .Part("grid", grid)
      .Part("diagnosis", diagnosis)
      .Part("joint", joint)
      .valid();
}

}  // namespace speckle
