#include "stages/chessboard_detection.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace speckle {
namespace {

cv::Mat ToGrey(const cv::Mat& image) {
  cv::Mat grey;
  if (image.type() == CV_8UC3) {
    cv::cvtColor(image, grey, cv::COLOR_RGB2GRAY);
  } else if (image.type() == CV_16UC1) {
    cv::normalize(image, grey, 0, 255, cv::NORM_MINMAX, CV_8U);
  } else {
    grey = image;
  }
  return grey;
}

double MeanSquarePx(const std::vector<cv::Point2f>& corners, cv::Size pattern) {
  double sum = 0;
  int n = 0;
  for (int j = 0; j < pattern.height; ++j)
    for (int i = 0; i + 1 < pattern.width; ++i, ++n)
      sum += cv::norm(corners[j * pattern.width + i + 1] - corners[j * pattern.width + i]);
  return n ? sum / n : 0;
}

// Puts square (0, 0) on the dark side: a 180-degree turn of the corner list
// otherwise flips which squares are dark and where the board's origin is.
void Canonicalize(std::vector<cv::Point2f>& corners, cv::Size pattern, const cv::Mat& grey) {
  const auto square_centre_shade = [&](const std::vector<cv::Point2f>& c) {
    const cv::Point2f first = c[0], along_x = c[1] - c[0], along_y = c[pattern.width] - c[0];
    const cv::Point2f centre = first - 0.5f * along_x - 0.5f * along_y;
    const cv::Point p(cvRound(centre.x), cvRound(centre.y));
    if (!cv::Rect(0, 0, grey.cols, grey.rows).contains(p)) return -1.0;
    return static_cast<double>(grey.at<std::uint8_t>(p));
  };
  std::vector<cv::Point2f> reversed(corners.rbegin(), corners.rend());
  const double forward = square_centre_shade(corners), backward = square_centre_shade(reversed);
  if (backward >= 0 && (forward < 0 || backward < forward - 20)) corners = reversed;
}

}  // namespace

StageResult<ChessboardDetection> RunChessboardDetection(const ChessboardDetectionOptions& options,
                                                        const BoardGeometry& board, const cv::Mat& image) {
  if (image.empty()) return Rejection{"chessboard", "no image in this frame"};
  const cv::Mat grey = ToGrey(image);
  const cv::Size pattern = board.InteriorCorners();
  std::vector<cv::Point2f> corners;
  bool found = false;
  if (options.try_half_resolution) {
    cv::Mat half;
    cv::pyrDown(grey, half);
    if (cv::findChessboardCornersSB(half, pattern, corners) &&
        2 * MeanSquarePx(corners, pattern) >= options.min_square_px_for_half) {
      for (auto& c : corners) c *= 2.0f;  // pyrDown centres output pixel i on input pixel 2i
      const int w = options.subpixel_window;
      cv::cornerSubPix(grey, corners, cv::Size(w, w), cv::Size(-1, -1),
                       cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 0.01));
      found = true;
    }
  }
  if (!found) found = cv::findChessboardCornersSB(grey, pattern, corners);
  if (!found) return Rejection{"chessboard", "no " + std::to_string(pattern.width) + "x" +
                                                 std::to_string(pattern.height) + " chessboard found"};
  Canonicalize(corners, pattern, grey);
  return ChessboardDetection{corners, image.size()};
}

}  // namespace speckle
