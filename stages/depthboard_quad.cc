#include "stages/depthboard_quad.h"

#include "schemas/option_check.h"
#include "stages/depth_region.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

namespace speckle {
namespace {

constexpr const char* kStage = "depthboard_quad";

Rejection Reject(std::string reason) { return {kStage, std::move(reason)}; }

// Line through edge pixels as (point, unit direction).
struct Line {
  Eigen::Vector2d point, direction;
};

std::optional<Eigen::Vector2d> Intersect(const Line& a, const Line& b) {
  Eigen::Matrix2d m;
  m << a.direction, -b.direction;
  if (std::abs(m.determinant()) < 1e-9) return std::nullopt;
  const Eigen::Vector2d t = m.colPivHouseholderQr().solve(b.point - a.point);
  return a.point + t.x() * a.direction;
}

// The 2 px band just outside a region: what the region borders on.
cv::Mat RingAround(const cv::Mat& region) {
  cv::Mat ring;
  cv::dilate(region, ring, cv::Mat(), cv::Point(-1, -1), 2);
  return ring & ~region;
}

// The board among the regions inside the gate that end at a depth step all
// round: the one whose area and place best match the predicted outline. The
// gate may hold the background wall, the floor or clutter as well, and with
// an uncertain camera the board need not be where the outline is predicted,
// so the region is chosen, not grown from the predicted centre.
StageResult<cv::Mat> SelectBoardRegion(const DepthboardQuadOptions& options, const cv::Mat& raw,
                                       const DepthReading& reading, const cv::Mat& gate,
                                       const std::array<Eigen::Vector2d, 4>& predicted, double uncertainty) {
  std::vector<cv::Point2f> outline;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const auto& c : predicted) outline.emplace_back(c.x(), c.y()), centre += c / 4;
  const double predicted_area = std::max(1.0, cv::contourArea(outline));
  cv::Mat values = StepValues(raw, reading);
  cv::Mat blocked;  // floodFill's mask, 2 px larger: outside the gate, no reading, or already visited
  cv::copyMakeBorder(~gate | NoReadingMask(raw, reading), blocked, 1, 1, 1, 1, cv::BORDER_CONSTANT, 255);
  const float step = static_cast<float>(options.max_step_raw);
  const cv::Rect bounds = cv::boundingRect(gate);
  cv::Mat best;
  double best_score = 1e18;
  int small = 0, open = 0;
  for (int v = bounds.y; v < bounds.br().y; v += 4) {
    for (int u = bounds.x; u < bounds.br().x; u += 4) {
      if (blocked.at<std::uint8_t>(v + 1, u + 1)) continue;
      cv::floodFill(values, blocked, {u, v}, cv::Scalar(), nullptr, cv::Scalar(step), cv::Scalar(step),
                    4 | cv::FLOODFILL_MASK_ONLY | (2 << 8));
      cv::Mat inner = blocked(cv::Rect(1, 1, raw.cols, raw.rows));
      const cv::Mat region = inner == 2;
      inner.setTo(1, region);  // visited
      const int pixels = cv::countNonZero(region);
      if (pixels < options.min_board_pixels) {
        ++small;
        continue;
      }
      // A region that runs into the gate's own border on most of its outline
      // is a wall or floor the gate cut out, not a board.
      const cv::Mat ring = RingAround(region);
      const int ring_pixels = cv::countNonZero(ring);
      if (ring_pixels == 0 || cv::countNonZero(ring & ~gate) > 0.3 * ring_pixels) {
        ++open;
        continue;
      }
      const cv::Moments m = cv::moments(region, true);
      const double off = (Eigen::Vector2d(m.m10 / m.m00, m.m01 / m.m00) - centre).norm();
      const double score =
          std::abs(std::log(pixels / predicted_area)) + off / (std::sqrt(predicted_area) + uncertainty);
      if (score < best_score) best_score = score, best = region;
    }
  }
  if (best.empty()) {
    if (open > 0) return Reject("no depth step around the board: the region runs into the position gate");
    if (small > 0)
      return Reject("no board-sized region inside the position gate (" + std::to_string(small) + " smaller ones)");
    return Reject("too few valid depth pixels where the board should be");
  }
  return best;
}

// Rejects a board region whose surroundings lie in the dark border: the
// sensor's view ends there, not the board.
std::optional<Rejection> CutByDarkBorder(const DepthboardQuadOptions& options, const cv::Mat& board,
                                         const cv::Mat* dark_border) {
  if (!dark_border || dark_border->size() != board.size()) return std::nullopt;
  const cv::Mat ring = RingAround(board);
  const int ring_pixels = cv::countNonZero(ring);
  const int dark = cv::countNonZero(ring & *dark_border);
  if (ring_pixels == 0 || dark <= options.max_dark_border_share * ring_pixels) return std::nullopt;
  return Reject("the board runs into the depth image's dark border (" + std::to_string(100 * dark / ring_pixels) +
                " % of its edge), where no frame has a reading: its outline there is the border's");
}

// Pixels to where an ideal camera with the same focal lengths and
// principal point sees them, and back: the identity without a camera or
// without distortion.
struct StraightImage {
  explicit StraightImage(const CameraIntrinsics* camera) {
    if (camera && std::any_of(camera->distortion.begin(), camera->distortion.end(), [](double k) { return k != 0; }))
      this->camera = camera;
  }
  Eigen::Vector2d FromPixel(const Eigen::Vector2d& pixel) const {
    if (!camera) return pixel;
    const Eigen::Vector2d xy = camera->Undistort(pixel);
    const cv::Matx33d& k = camera->camera_matrix;
    return {k(0, 0) * xy.x() + k(0, 2), k(1, 1) * xy.y() + k(1, 2)};
  }
  Eigen::Vector2d ToPixel(const Eigen::Vector2d& straight) const {
    if (!camera) return straight;
    const cv::Matx33d& k = camera->camera_matrix;
    return camera->Project({(straight.x() - k(0, 2)) / k(0, 0), (straight.y() - k(1, 2)) / k(1, 1), 1.0});
  }
  const CameraIntrinsics* camera = nullptr;
};

// The median raw value over the board's pixels.
double MedianRaw(const cv::Mat& raw, const cv::Mat& board) {
  std::vector<std::uint16_t> board_raw;
  for (int v = 0; v < raw.rows; ++v)
    for (int u = 0; u < raw.cols; ++u)
      if (board.at<std::uint8_t>(v, u)) board_raw.push_back(raw.at<std::uint16_t>(v, u));
  std::nth_element(board_raw.begin(), board_raw.begin() + static_cast<std::ptrdiff_t>(board_raw.size() / 2),
                   board_raw.end());
  return board_raw[board_raw.size() / 2];
}

// The board region's outer contour and the quadrilateral it approximates.
struct Outline {
  std::vector<cv::Point> contour, polygon;
};

StageResult<Outline> OutlineOf(const cv::Mat& board) {
  Outline out;
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(board.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  out.contour = *std::max_element(contours.begin(), contours.end(),
                                  [](const auto& a, const auto& b) { return a.size() < b.size(); });
  std::vector<cv::Point> hull;
  cv::convexHull(out.contour, hull);
  cv::approxPolyDP(hull, out.polygon, 0.03 * cv::arcLength(hull, true), true);
  if (out.polygon.size() != 4)
    return Reject("the board's outline is not a quadrilateral (" + std::to_string(out.polygon.size()) + " sides)");
  for (const auto& p : out.polygon)
    if (p.x <= 1 || p.y <= 1 || p.x >= board.cols - 2 || p.y >= board.rows - 2)
      return Reject("the board is cut by the image border");
  return out;
}

// Sub-pixel sides: edge pixels between consecutive vertices, each moved
// half a pixel outwards (the step lies between the last board pixel centre
// and the first outside one), and a line through them in the straight
// image. `line_rms`: the edge pixels' scatter about their lines.
StageResult<std::array<Line, 4>> FitSides(const DepthboardQuadOptions& options, const Outline& outline,
                                          const StraightImage& straight, double& line_rms) {
  const std::vector<cv::Point>& polygon = outline.polygon;
  std::array<Line, 4> sides;
  double squared_scatter = 0;
  int edge_count = 0;
  Eigen::Vector2d polygon_centre = Eigen::Vector2d::Zero();
  for (const auto& p : polygon) polygon_centre += Eigen::Vector2d(p.x, p.y) / 4;
  for (int s = 0; s < 4; ++s) {
    const Eigen::Vector2d a(polygon[s].x, polygon[s].y), b(polygon[(s + 1) % 4].x, polygon[(s + 1) % 4].y);
    const Eigen::Vector2d along = (b - a).normalized();
    Eigen::Vector2d normal(-along.y(), along.x());
    const Eigen::Vector2d outward = (a - polygon_centre).dot(normal) > 0 ? normal : Eigen::Vector2d(-normal);
    std::vector<cv::Point2f> edge;
    for (const auto& p : outline.contour) {
      const Eigen::Vector2d q(p.x, p.y);
      const double t = (q - a).dot(along), off = std::abs((q - a).dot(normal));
      if (off < 2.5 && t > options.side_trim_px && t < (b - a).norm() - options.side_trim_px) {
        const Eigen::Vector2d e = straight.FromPixel(q + 0.5 * outward);
        edge.emplace_back(static_cast<float>(e.x()), static_cast<float>(e.y()));
      }
    }
    if (edge.size() < 8) return Reject("side " + std::to_string(s) + " of the outline has too few edge pixels");
    cv::Vec4f fitted;
    cv::fitLine(edge, fitted, cv::DIST_HUBER, 0, 0.01, 0.01);
    Line line{{fitted[2], fitted[3]}, {fitted[0], fitted[1]}};
    const Eigen::Vector2d line_normal(-line.direction.y(), line.direction.x());
    for (const auto& e : edge) {
      squared_scatter += std::pow((Eigen::Vector2d(e.x, e.y) - line.point).dot(line_normal), 2);
      ++edge_count;
    }
    sides[static_cast<std::size_t>(s)] = line;
  }
  line_rms = std::sqrt(squared_scatter / edge_count);
  if (line_rms > options.max_line_rms_px)
    return Reject("the outline's sides are not straight (edge scatter " + std::to_string(line_rms) + " px)");
  return sides;
}

// The corners where consecutive sides meet, back in the depth image.
StageResult<std::array<Eigen::Vector2d, 4>> Corners(const std::array<Line, 4>& sides, const StraightImage& straight) {
  std::array<Eigen::Vector2d, 4> found;
  for (int s = 0; s < 4; ++s) {
    const auto corner = Intersect(sides[(s + 3) % 4], sides[static_cast<std::size_t>(s)]);
    if (!corner)
      return Reject(
          "two sides of the outline are parallel: the region found is not the board's four sides (a board seen "
          "nearly edge-on, or a depth camera whose lens is far off)");
    found[static_cast<std::size_t>(s)] = straight.ToPixel(*corner);
  }
  return found;
}

// The corners ordered like the predicted outline: the cyclic rotation and
// direction with the smallest total distance.
std::array<Eigen::Vector2d, 4> OrderedLike(const std::array<Eigen::Vector2d, 4>& found,
                                           const std::array<Eigen::Vector2d, 4>& predicted) {
  std::array<Eigen::Vector2d, 4> best;
  double best_total = 1e18;
  for (int direction : {1, -1}) {
    for (int shift = 0; shift < 4; ++shift) {
      double total = 0;
      std::array<Eigen::Vector2d, 4> ordered;
      for (int k = 0; k < 4; ++k) {
        ordered[static_cast<std::size_t>(k)] = found[static_cast<std::size_t>(((shift + direction * k) % 4 + 4) % 4)];
        total += (ordered[static_cast<std::size_t>(k)] - predicted[static_cast<std::size_t>(k)]).norm();
      }
      if (total < best_total) best_total = total, best = ordered;
    }
  }
  return best;
}

}  // namespace

StageResult<DepthboardQuad> RunDepthboardQuadExtraction(const DepthboardQuadOptions& options,
                                                        const DepthboardQuadInput& input) {
  const cv::Mat& raw = input.raw;
  if (raw.empty()) return Reject(kNoDepthImage);
  // Position gate: the predicted outline, grown by the margin and by how far
  // the prediction itself may be off.
  const double uncertainty = std::max(0.0, input.prediction_uncertainty_px);
  const cv::Mat gate = GatePolygon(raw.size(), input.predicted_corners_px, options.gate_margin_px + uncertainty);
  if (cv::countNonZero(gate) == 0) return Reject("the board is predicted outside the depth image");
  auto selected = SelectBoardRegion(options, raw, input.reading, gate, input.predicted_corners_px, uncertainty);
  if (!Accepted(selected)) return std::get<Rejection>(selected);
  const cv::Mat board = std::get<cv::Mat>(selected);
  if (auto cut = CutByDarkBorder(options, board, input.dark_border)) return *cut;
  const auto outline = OutlineOf(board);
  if (!Accepted(outline)) return std::get<Rejection>(outline);
  const StraightImage straight(input.camera);
  double line_rms = 0;
  const auto sides = FitSides(options, std::get<Outline>(outline), straight, line_rms);
  if (!Accepted(sides)) return std::get<Rejection>(sides);
  const auto found = Corners(std::get<std::array<Line, 4>>(sides), straight);
  if (!Accepted(found)) return std::get<Rejection>(found);
  DepthboardQuad quad;
  quad.corners_px = OrderedLike(std::get<std::array<Eigen::Vector2d, 4>>(found), input.predicted_corners_px);
  for (int k = 0; k < 4; ++k) {
    const double shift = (quad.corners_px[k] - input.predicted_corners_px[k]).norm();
    if (shift > options.max_corner_shift_px + uncertainty) {
      return Reject("outline corner " + std::to_string(k) + " is " + std::to_string(static_cast<int>(shift)) +
                    " px from where the colour pose puts it");
    }
  }
  quad.board_raw_median = MedianRaw(raw, board);
  quad.board_pixels = cv::countNonZero(board);
  quad.line_fit_rms_px = line_rms;
  return quad;
}

bool DepthboardQuadOptions::IsValid(std::string* why) const {
  return OptionCheck(why)
      .AtLeast(gate_margin_px, 0, "gate_margin_px")
      .Positive(max_step_raw, "max_step_raw")
      .AtLeast(min_board_pixels, 1, "min_board_pixels")
      .Positive(max_corner_shift_px, "max_corner_shift_px")
      .AtLeast(side_trim_px, 0, "side_trim_px")
      .Positive(max_line_rms_px, "max_line_rms_px")
      .Share(max_dark_border_share, "max_dark_border_share")
      .valid();
}

}  // namespace speckle
