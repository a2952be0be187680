#pragma once
// Stage 3: the depthboard's outline in a raw depth image (thesis chapter 3):
// gate by position around where the colour pose puts the board, gate by
// depth by taking the region inside it that ends at a depth step all round
// and best matches the predicted outline, take its contour and quadrilateral, then refine
// each side to sub-pixel accuracy by fitting a line to the depth step along
// it (in the undistorted image when the camera is known) and intersecting
// neighbouring sides.
#include <opencv2/core.hpp>
#include <string>

#include "stages/records.h"

namespace speckle {

struct DepthboardQuadOptions {
  double gate_margin_px = 15;  // position gate: predicted outline grown by this
  double max_step_raw = 6;     // neighbouring board pixels differ by less (a tilted board)
  int min_board_pixels = 250;
  double max_corner_shift_px = 25;  // found corners may be this far from the predicted ones
  int side_trim_px = 4;             // ignore edge pixels this close to a vertex when fitting a side
  double max_line_rms_px = 1.5;     // a side whose edge pixels scatter more is not a straight step
  // A board whose surroundings lie this much in the dark border is cut by it
  // (a pixel or two where a corner touches it moves no side).
  double max_dark_border_share = 0.01;
  // False, naming the first broken rule's field in *why (schemas/option_check.h).
  bool IsValid(std::string* why) const;
};

struct DepthboardQuadInput {
  const cv::Mat& raw;                                   // CV_16UC1 in the recording's units (`reading`)
  std::array<Eigen::Vector2d, 4> predicted_corners_px;  // outline corners from the colour pose
  // How far the prediction may be off (an uncertain depth camera): the gate
  // and the corner check widen by this.
  double prediction_uncertainty_px = 0;
  // The depth camera, when its distortion is known: a board's straight sides
  // are straight only once undistorted (a wide-angle lens bows them by
  // pixels), so each side is fitted there and the corners distorted back.
  const CameraIntrinsics* camera = nullptr;
  // The session's dark border (stages/dark_border.h), when known: a board
  // running into it is rejected, not outlined along the border.
  const cv::Mat* dark_border = nullptr;
  DepthReading reading{};  // the recording's units: which values are no reading
};

StageResult<DepthboardQuad> RunDepthboardQuadExtraction(const DepthboardQuadOptions& options,
                                                        const DepthboardQuadInput& input);

}  // namespace speckle
