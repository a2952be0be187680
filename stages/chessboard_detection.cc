#include "stages/chessboard_detection.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>

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

StageResult<ChessboardDetection> RunChessboardTracking(const ChessboardTrackingOptions& options,
                                                       const BoardGeometry& board, const cv::Mat& image,
                                                       const ChessboardDetection& previous) {
  if (image.empty()) return Rejection{"chessboard", "no image in this frame"};
  const cv::Mat grey = ToGrey(image);
  std::vector<cv::Point2f> corners = previous.corners;
  const int w = options.subpixel_window;
  cv::cornerSubPix(grey, corners, cv::Size(w, w), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 0.01));
  double motion = 0;
  for (std::size_t k = 0; k < corners.size(); ++k) motion += cv::norm(corners[k] - previous.corners[k]);
  if (motion / static_cast<double>(corners.size()) > options.max_motion_px) {
    return Rejection{"chessboard_tracking", "the board moved"};
  }
  // The corners must still be chessboard corners: at each, the diagonal
  // quadrants alike and the neighbouring ones different (cornerSubPix leaves
  // corners where they were on a featureless image).
  const float reach = static_cast<float>(0.3 * cv::norm(corners[1] - corners[0]));
  std::vector<double> contrast;
  const cv::Rect inside(0, 0, grey.cols, grey.rows);
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const cv::Point2f along_x = (k + 1 < corners.size() ? corners[k + 1] - corners[k] : corners[k] - corners[k - 1]);
    const cv::Point2f ux = along_x * (reach / static_cast<float>(std::max(1e-6, cv::norm(along_x))));
    const cv::Point2f uy(-ux.y, ux.x);
    double q[4] = {};
    bool ok = true;
    const cv::Point2f offsets[4] = {ux + uy, -ux - uy, ux - uy, -ux + uy};
    for (int i = 0; i < 4; ++i) {
      const cv::Point p(cvRound(corners[k].x + offsets[i].x), cvRound(corners[k].y + offsets[i].y));
      if (!inside.contains(p))
        ok = false;
      else
        q[i] = grey.at<std::uint8_t>(p);
    }
    if (ok) contrast.push_back(std::abs((q[0] + q[1]) - (q[2] + q[3])) / 2);
  }
  if (contrast.empty()) return Rejection{"chessboard_tracking", "the corners left the image"};
  std::nth_element(contrast.begin(), contrast.begin() + static_cast<std::ptrdiff_t>(contrast.size() / 2),
                   contrast.end());
  if (contrast[contrast.size() / 2] < options.min_corner_contrast) {
    return Rejection{"chessboard_tracking", "no chessboard corners where the board was"};
  }
  // A planar grid seen by a camera maps to the image by a homography (lens
  // distortion is small over one board at this tolerance's scale).
  std::vector<cv::Point2f> grid;
  for (const auto& p : board.InteriorCornerPoints()) grid.emplace_back(p.x, p.y);
  const cv::Mat h = cv::findHomography(grid, corners);
  if (h.empty()) return Rejection{"chessboard_tracking", "no homography"};
  std::vector<cv::Point2f> mapped;
  cv::perspectiveTransform(grid, mapped, h);
  double squared = 0;
  for (std::size_t k = 0; k < corners.size(); ++k) squared += std::pow(cv::norm(mapped[k] - corners[k]), 2);
  if (std::sqrt(squared / static_cast<double>(corners.size())) > options.max_homography_rms_px) {
    return Rejection{"chessboard_tracking", "the refined corners no longer form the board's grid"};
  }
  return ChessboardDetection{corners, image.size()};
}

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
    if (cv::findChessboardCornersSB(half, pattern, corners)) {
      for (auto& c : corners) c *= 2.0f;  // pyrDown centres output pixel i on input pixel 2i
      const double square_px = MeanSquarePx(corners, pattern);
      if (square_px >= options.min_square_px_for_half) {
        found = true;  // large enough to refine the half-resolution corners in place
      } else {
        // Too small to refine from half resolution: search full resolution,
        // but only around where the board was found.
        cv::Rect roi = cv::boundingRect(corners);
        const int margin = static_cast<int>(std::ceil(2.5 * square_px));
        roi = cv::Rect(roi.x - margin, roi.y - margin, roi.width + 2 * margin, roi.height + 2 * margin) &
              cv::Rect(0, 0, grey.cols, grey.rows);
        if (cv::findChessboardCornersSB(grey(roi).clone(), pattern, corners)) {
          for (auto& c : corners) c += cv::Point2f(static_cast<float>(roi.x), static_cast<float>(roi.y));
          found = true;
        }
      }
    }
  }
  if (!found) found = cv::findChessboardCornersSB(grey, pattern, corners);
  // Last, the detector's upsampled search: a small board tilted 30 degrees
  // and more has squares of 6 to 8 px along its foreshortened side, which only
  // it finds (about 0.15 s, spent only on frames nothing else found).
  if (!found) found = cv::findChessboardCornersSB(grey, pattern, corners, cv::CALIB_CB_ACCURACY);
  // And the classic detector, whose adaptive thresholds find steeply tilted
  // boards in large, unevenly lit images that the SB detector misses
  // (Herrera's 1280x1024 frames 20-25 and 65).
  if (!found) {
    found =
        cv::findChessboardCorners(grey, pattern, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
  }
  if (!found)
    return Rejection{"chessboard", "no " + std::to_string(pattern.width) + "x" + std::to_string(pattern.height) +
                                       " chessboard found"};
  // Always refine at full resolution: on squares of 7 to 10 px the SB
  // detector's own corners make the board 0.1 to 0.6 % too large (simulated
  // truth; cornerSubPix's are within 0.02 %), which biased the colour focal
  // length by 0.7 % and, mixed with tracked frames' refined corners, made each
  // pose's scale depend on how it was found. The window stays inside the
  // corner's four squares.
  const int w = std::clamp(static_cast<int>(0.4 * MeanSquarePx(corners, pattern)), 2, options.subpixel_window);
  cv::cornerSubPix(grey, corners, cv::Size(w, w), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 0.01));
  Canonicalize(corners, pattern, grey);
  return ChessboardDetection{corners, image.size()};
}

}  // namespace speckle
