#include "stages/chessboard_detection.h"

#include "schemas/option_check.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

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

// How far a corner is from its squares' far edges: the mean of each square's
// smaller height (area over its longer side). A board tilted steeply is
// foreshortened along one axis, and one seen obliquely is sheared, its
// squares thin parallelograms whose sides stay long.
double SquareHeightPx(const std::vector<cv::Point2f>& corners, cv::Size pattern) {
  double sum = 0;
  for (int j = 0; j + 1 < pattern.height; ++j)
    for (int i = 0; i + 1 < pattern.width; ++i) {
      const cv::Point2f& c = corners[j * pattern.width + i];
      const cv::Point2f d = corners[j * pattern.width + i + 1] - c, e = corners[(j + 1) * pattern.width + i] - c;
      sum += std::abs(d.cross(e)) / std::max(cv::norm(d), cv::norm(e));
    }
  return sum / ((pattern.width - 1) * (pattern.height - 1));
}

// The image at twice its resolution (cubic), and corners moved between the
// two: output pixel i is centred on input position (i + 0.5) / 2 - 0.5.
cv::Mat Twice(const cv::Mat& grey) {
  cv::Mat twice;
  cv::resize(grey, twice, cv::Size(), 2, 2, cv::INTER_CUBIC);
  return twice;
}
void ToTwice(std::vector<cv::Point2f>& corners) {
  for (auto& c : corners) c = 2.0f * c + cv::Point2f(0.5f, 0.5f);
}
void FromTwice(std::vector<cv::Point2f>& corners) {
  for (auto& c : corners) c = 0.5f * c - cv::Point2f(0.25f, 0.25f);
}

// How far the corners are from the nearest planar grid's image (RMS px): a
// homography fitted to them by least squares. Lens distortion adds a share
// that depends only on where the board is, so it is the same for every window.
double GridResidualPx(const std::vector<cv::Point2f>& corners, cv::Size pattern) {
  std::vector<cv::Point2f> grid;
  for (int j = 0; j < pattern.height; ++j)
    for (int i = 0; i < pattern.width; ++i) grid.emplace_back(static_cast<float>(i), static_cast<float>(j));
  const cv::Mat h = cv::findHomography(grid, corners);
  if (h.empty()) return std::numeric_limits<double>::infinity();
  std::vector<cv::Point2f> mapped;
  cv::perspectiveTransform(grid, mapped, h);
  double squared = 0;
  for (std::size_t k = 0; k < corners.size(); ++k) squared += std::pow(cv::norm(mapped[k] - corners[k]), 2);
  return std::sqrt(squared / static_cast<double>(corners.size()));
}

// cornerSubPix with its window inside the corner's four squares, which it
// must not leave: a wider one pulls the corner towards its neighbours (2.7 px
// on a board foreshortened to 3 px squares; 0.58 px RMS against its grid
// where 0.26 with the window its squares' height allows on a sheared one of
// 7.5 px sides and 5.4 px height). Squares under 5 px high are refined
// at twice the resolution, where the smallest window still fits (drawn
// boards of 2-4.5 px squares: 0.13-0.34 px RMS there, up to 0.6-27 px in
// place).
// Within that, the window is 0.4 to 0.6 of the squares' height, whichever
// leaves the corners nearest a planar grid. A window too narrow for the
// image's blur errs by a pattern that alternates with the corners' parity;
// one too wide jumps off corners; both leave the grid. A fixed 0.4 measured
// 0.28 px median from the truth on a far wide-angle board of 4.7 px squares
// (room seed 22, frame 1); the grid chose 0.6 there, 0.135 px.
// The other windows' corners are kept in `others`.
void RefineCorners(const cv::Mat& grey, cv::Size pattern, int max_window, std::vector<cv::Point2f>& corners,
                   std::vector<std::vector<cv::Point2f>>& others) {
  const double side = SquareHeightPx(corners, pattern);
  const bool at_twice = side < 5;
  if (at_twice) ToTwice(corners);
  const cv::Mat image = at_twice ? Twice(grey) : grey;
  const double scale = at_twice ? 2 * side : side;
  const auto window = [&](double share) { return std::clamp(static_cast<int>(share * scale), 2, max_window); };
  std::vector<std::vector<cv::Point2f>> refined;
  std::vector<double> residuals;
  for (int w = window(0.4); w <= window(0.6); ++w) {
    refined.push_back(corners);
    cv::cornerSubPix(image, refined.back(), cv::Size(w, w), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 0.01));
    if (at_twice) FromTwice(refined.back());
    residuals.push_back(GridResidualPx(refined.back(), pattern));
  }
  const auto best = std::min_element(residuals.begin(), residuals.end()) - residuals.begin();
  corners = refined[static_cast<std::size_t>(best)];
  others.clear();
  for (std::size_t k = 0; k < refined.size(); ++k)
    if (k != static_cast<std::size_t>(best)) others.push_back(std::move(refined[k]));
}

// Puts square (0, 0) on the dark side: a 180-degree turn of the corner list
// otherwise flips which squares are dark and where the board's origin is.
// The other refinements turn with the corners.
void Canonicalize(std::vector<cv::Point2f>& corners, cv::Size pattern, const cv::Mat& grey,
                  std::vector<std::vector<cv::Point2f>>& others) {
  const auto square_centre_shade = [&](const std::vector<cv::Point2f>& c) {
    const cv::Point2f first = c[0], along_x = c[1] - c[0], along_y = c[pattern.width] - c[0];
    const cv::Point2f centre = first - 0.5f * along_x - 0.5f * along_y;
    const cv::Point p(cvRound(centre.x), cvRound(centre.y));
    if (!cv::Rect(0, 0, grey.cols, grey.rows).contains(p)) return -1.0;
    return static_cast<double>(grey.at<std::uint8_t>(p));
  };
  std::vector<cv::Point2f> reversed(corners.rbegin(), corners.rend());
  const double forward = square_centre_shade(corners), backward = square_centre_shade(reversed);
  if (backward >= 0 && (forward < 0 || backward < forward - 20)) {
    corners = reversed;
    for (auto& other : others) std::reverse(other.begin(), other.end());
  }
}

// The detector at twice the resolution (cubic): a far board in a wide-angle
// colour image has squares of 4 to 6 px, which it misses at their own size
// (the wide-angle benchmark's seed 7 lost 6 of 72 frames so). 0.1-0.3 s a
// VGA frame, spent only on frames the detector missed, and before the classic
// detector, which took 11 s on each such drawn frame.
bool FindUpsampled(const cv::Mat& grey, cv::Size pattern, std::vector<cv::Point2f>& corners) {
  if (!cv::findChessboardCornersSB(Twice(grey), pattern, corners)) return false;
  FromTwice(corners);
  return true;
}

}  // namespace

StageResult<ChessboardDetection> RunChessboardTracking(const ChessboardTrackingOptions& options,
                                                       const BoardGeometry& board, const cv::Mat& image,
                                                       const ChessboardDetection& previous) {
  if (image.empty()) return Rejection{"chessboard", "no image in this frame"};
  const cv::Mat grey = ToGrey(image);
  const cv::Size pattern = board.InteriorCorners();
  std::vector<cv::Point2f> corners = previous.corners;
  std::vector<std::vector<cv::Point2f>> others;
  RefineCorners(grey, pattern, options.subpixel_window, corners, others);
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
  if (GridResidualPx(corners, pattern) > options.max_homography_rms_px) {
    return Rejection{"chessboard_tracking", "the refined corners no longer form the board's grid"};
  }
  return ChessboardDetection{corners, image.size(), std::move(others)};
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
  if (!found && grey.cols <= options.max_width_to_upsample) found = FindUpsampled(grey, pattern, corners);
  if (!found) {
    found =
        cv::findChessboardCorners(grey, pattern, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
  }
  if (!found)
    return Rejection{"chessboard", "no " + std::to_string(pattern.width) + "x" + std::to_string(pattern.height) +
                                       " chessboard found"};
  // Always refine: on squares of 7 to 10 px the SB detector's own corners
  // make the board 0.1 to 0.6 % too large (simulated truth; cornerSubPix's
  // are within 0.02 %), which biased the colour focal length by 0.7 % and,
  // mixed with tracked frames' refined corners, made each pose's scale depend
  // on how it was found.
  std::vector<std::vector<cv::Point2f>> others;
  RefineCorners(grey, pattern, options.subpixel_window, corners, others);
  Canonicalize(corners, pattern, grey, others);
  return ChessboardDetection{corners, image.size(), std::move(others)};
}

bool ChessboardDetectionOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .Positive(min_square_px_for_half, "min_square_px_for_half")
      .AtLeast(subpixel_window, 1, "subpixel_window")
      .AtLeast(max_width_to_upsample, 0, "max_width_to_upsample")
      .valid();
}

bool ChessboardTrackingOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .Positive(max_motion_px, "max_motion_px")
      .Positive(max_homography_rms_px, "max_homography_rms_px")
      .AtLeast(min_corner_contrast, 0, "min_corner_contrast")
      .AtLeast(subpixel_window, 1, "subpixel_window")
      .valid();
}

}  // namespace speckle
