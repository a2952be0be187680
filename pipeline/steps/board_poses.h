#pragma once
// Board frames grouped into still poses, and their motion: what the camera
// step does to the colour detections before the cameras are calibrated.
#include <Eigen/Core>

#include "pipeline/frame_work.h"

namespace speckle {

// Groups consecutive frames of a still board (corners moved at most
// `still_motion_px`) and measures corner motion. The image velocity comes
// from any two consecutive frames of a board, still or not: a hand-held
// board drifting a few pixels a frame splits into one-frame poses, yet its
// velocity is what a capture-time offset needs. Sorts `boards` by index.
void AssignPoses(std::vector<Frame>& boards, double still_motion_px, double max_velocity_gap_s);

// Each board frame's velocity from the colour poses of two other frames of
// its run (see RateNeighbours), boards in recording order.
void AssignBoardMotion(std::vector<Frame>& boards, const Eigen::Vector3d& centre_in_board, double max_gap_s);

// Gives each board frame the raw frames of up to `window` consecutive frames
// of its still pose, centred on it, for the quad to be found in their median.
void GatherStillNeighbours(std::vector<Frame>& boards, int window);

}  // namespace speckle
