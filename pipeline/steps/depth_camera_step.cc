#include "pipeline/steps/depth_camera_step.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>
#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "stages/camera_calibration.h"
#include "stages/depth_region.h"

namespace speckle {
namespace {

constexpr int kMaxFinePasses = 3;
// Focal lengths (shares of nominal) tried when the nominal camera finds few outlines.
constexpr double kShorterFocalPriors[] = {0.8, 0.64};
// Board pixels for the camera's fit: away from the mixed pixels of the edge,
// and sparse enough that a fit over 20 poses takes a fraction of a second.
constexpr double kBoardPixelInsetPx = 5;
constexpr int kBoardPixelStride = 8;

// The frames with an outline as views, each with its board pixels.
std::vector<ExtrinsicsView> Views(const std::vector<OutlineFrame>& frames,
                                  const std::vector<std::optional<DepthboardQuad>>& quads,
                                  const DepthReading& reading) {
  std::vector<ExtrinsicsView> views;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (!quads[i]) continue;
    std::vector<Eigen::Vector3d> pixels;
    if (frames[i].raw)
      pixels = BoardPixels(frames[i].raw->Image(), *quads[i], kBoardPixelInsetPx, kBoardPixelStride, reading);
    views.push_back({frames[i].colour_from_board, *quads[i], frames[i].board_velocity, std::move(pixels)});
  }
  return views;
}

std::vector<StageResult<DepthboardQuad>> AsResults(const std::vector<std::optional<DepthboardQuad>>& quads) {
  std::vector<StageResult<DepthboardQuad>> out;
  for (const auto& q : quads) {
    if (q)
      out.emplace_back(*q);
    else
      out.emplace_back(Rejection{"depthboard_quad", "no outline found where the nominal camera puts it"});
  }
  return out;
}

// The colour camera's intrinsics give every board pose: each moved by one
// sigma, the poses found again and the depth camera refitted; what that moves
// the depth camera by adds to its standard deviations. A colour focal length
// off by 0.3 % puts every board 0.3 % too near, and the depth focal lengths
// follow it; no spread over poses shows that.
void AddColourCameraUncertainty(const ExtrinsicsOptions& options, const DepthReading& reading,
                                const BoardGeometry& board, const CameraIntrinsics& colour,
                                const std::vector<OutlineFrame>& frames, DepthCameraStepResult& out) {
  // Three moves: the focal length (fx and fy together: their errors go
  // together, and moving one alone would change the aspect ratio, which no
  // calibration leaves that uncertain), then each principal point coordinate.
  std::vector<std::optional<ExtrinsicsResult>> moved(3);
  tbb::parallel_for(0, 3, [&](int input) {
    CameraIntrinsics c = colour;
    if (input == 0) {
      c.camera_matrix(0, 0) += colour.stddev[0];
      c.camera_matrix(1, 1) += colour.stddev[1];
    } else {
      c.camera_matrix(input - 1, 2) += colour.stddev[static_cast<std::size_t>(input + 1)];
    }
    if (c.camera_matrix == colour.camera_matrix) return;  // no uncertainty given
    std::vector<ExtrinsicsView> views;
    for (std::size_t i = 0; i < frames.size(); ++i) {
      if (!Accepted(out.quads[i]) || !frames[i].detection) continue;
      ExtrinsicsView v = out.views[views.size()];
      v.colour_from_board = BoardPose(c, board, *frames[i].detection);
      views.push_back(std::move(v));
    }
    moved[static_cast<std::size_t>(input)] = RefitDepthCamera(options, reading, board, views, out.extrinsics);
  });
  for (const auto& m : moved) {
    if (!m) continue;
    for (int i = 0; i < kFittedValues; ++i) {
      double& sigma = FittedSigma(out.extrinsics, i);
      sigma = std::hypot(sigma, FittedValue(*m, i) - FittedValue(out.extrinsics, i));
    }
  }
}

int Count(const std::vector<std::optional<DepthboardQuad>>& quads) {
  return static_cast<int>(std::count_if(quads.begin(), quads.end(), [](const auto& q) { return q.has_value(); }));
}

// A camera far from nominal (an add-on wide-angle lens: fx near 370 px for
// the stock 580) leaves most of the first gates empty. Then the outlines are
// searched again from shorter focal lengths, with gates as wide as such a
// prior is uncertain, and the prior that finds the most is the fit's start.
CameraIntrinsics WiderPriorIfNeeded(const std::vector<OutlineFrame>& frames, const CameraIntrinsics& nominal,
                                    const Eigen::Isometry3d& depth_from_colour,
                                    std::vector<std::optional<DepthboardQuad>>& coarse) {
  CameraIntrinsics best = nominal;
  for (double scale : kShorterFocalPriors) {
    if (2 * Count(coarse) >= static_cast<int>(frames.size())) break;
    CameraIntrinsics prior = nominal;
    prior.camera_matrix(0, 0) *= scale;
    prior.camera_matrix(1, 1) *= scale;
    prior.stddev = {0.03 * prior.camera_matrix(0, 0), 0.03 * prior.camera_matrix(1, 1), 10, 10};
    std::vector<std::optional<DepthboardQuad>> found(frames.size());
    tbb::parallel_for(std::size_t{0}, frames.size(), [&](std::size_t i) {
      auto quad = frames[i].find_outline(prior, depth_from_colour);
      if (Accepted(quad)) found[i] = std::get<DepthboardQuad>(std::move(quad));
    });
    spdlog::info("depthboard outlines from a {:.0f} px prior: {} of {}", prior.camera_matrix(0, 0), Count(found),
                 frames.size());
    if (Count(found) > Count(coarse)) coarse = std::move(found), best = prior;
  }
  best.stddev = {};
  return best;
}

}  // namespace

std::vector<Eigen::Vector3d> BoardPixels(const cv::Mat& raw, const DepthboardQuad& quad, double inset_px, int stride,
                                         const DepthReading& reading) {
  const cv::Mat inside = GatePolygon(raw.size(), quad.corners_px, -inset_px);
  std::vector<Eigen::Vector3d> pixels;
  for (int v = 0; v < raw.rows; v += stride)
    for (int u = 0; u < raw.cols; u += stride)
      if (inside.at<std::uint8_t>(v, u) && reading.IsReading(raw.at<std::uint16_t>(v, u)))
        pixels.emplace_back(u, v, raw.at<std::uint16_t>(v, u));
  return pixels;
}

std::optional<std::string> LooselyPinned(const ExtrinsicsOptions& options, const CameraIntrinsics& d,
                                         const std::string& what) {
  const auto& s = d.stddev;
  const bool focal = s[0] > options.max_focal_sigma_share * d.camera_matrix(0, 0) ||
                     s[1] > options.max_focal_sigma_share * d.camera_matrix(1, 1);
  const bool centre = std::max(s[2], s[3]) > options.max_principal_point_sigma_px;
  if (!focal && !centre) return std::nullopt;
  return fmt::format(
      "the depth camera is known only loosely from {} ({} views; fx {:.1f} ± {:.1f}, fy {:.1f} ± {:.1f}, "
      "cx {:.1f} ± {:.1f}, cy {:.1f} ± {:.1f} px), and every depth inherits that: record more board poses, from near "
      "to far and out to the image's corners, tilted up to "
      "30 degrees, or an IR chessboard recording (record-session freenect --purpose ir_chessboard --add-to SESSION)",
      what, d.views, d.camera_matrix(0, 0), s[0], d.camera_matrix(1, 1), s[1], d.camera_matrix(0, 2), s[2],
      d.camera_matrix(1, 2), s[3]);
}

double PredictionUncertaintyPx(const CameraIntrinsics& camera, const std::array<Eigen::Vector2d, 4>& corners) {
  const auto& s = camera.stddev;  // fx, fy, cx, cy, k1, k2, p1, p2, k3
  double r = 0;
  for (const auto& c : corners) r = std::max(r, camera.Undistort(c).norm());
  if (!std::isfinite(r)) r = 1;
  const double f = std::max(camera.camera_matrix(0, 0), camera.camera_matrix(1, 1)), r2 = r * r;
  const double lens = r * (s[4] * r2 + s[5] * r2 * r2 + s[8] * r2 * r2 * r2) + 3 * (s[6] + s[7]) * r2;
  return 3 * (std::hypot(s[2], s[3]) + std::max(s[0], s[1]) * r + f * lens);
}

StageResult<DepthboardQuad> FindOutline(const PipelineOptions& options, const std::vector<RawDepth>& still_frames,
                                        const RawDepth& raw, const std::array<Eigen::Vector2d, 4>& predicted,
                                        double uncertainty_px, const CameraIntrinsics* camera,
                                        const cv::Mat* dark_border) {
  if (still_frames.size() <= 1)
    return RunDepthboardQuadExtraction(options.quad,
                                       {raw.Image(), predicted, uncertainty_px, camera, dark_border, options.reading});
  std::vector<cv::Mat> images;
  for (const RawDepth& r : still_frames) images.push_back(r.Image());
  auto averaged = RunStillFrameAverage(options.still_average, images, options.reading);
  if (!Accepted(averaged)) return std::get<Rejection>(averaged);
  return RunDepthboardQuadExtraction(
      options.quad, {std::get<cv::Mat>(averaged), predicted, uncertainty_px, camera, dark_border, options.reading});
}

DepthCameraStepResult CalibrateDepthCameraFromOutlines(const ExtrinsicsOptions& options, const DepthReading& reading,
                                                       const BoardGeometry& board, const CameraIntrinsics& colour,
                                                       const CameraIntrinsics& nominal,
                                                       const Eigen::Isometry3d& initial_depth_from_colour,
                                                       std::vector<OutlineFrame>& frames) {
  DepthCameraStepResult out;
  out.depth = nominal;
  std::vector<std::optional<DepthboardQuad>> coarse;
  for (const auto& f : frames) coarse.push_back(f.quad);
  const CameraIntrinsics prior = WiderPriorIfNeeded(frames, nominal, initial_depth_from_colour, coarse);
  auto fitted = RunDepthCameraFromOutlines(options, reading, board, prior, Views(frames, coarse, reading),
                                           initial_depth_from_colour);
  if (!Accepted(fitted)) {
    out.not_fitted = std::get<Rejection>(fitted).reason;
    out.extrinsics = RunExtrinsicsCalibration(options, reading, board, nominal, Views(frames, coarse, reading),
                                              initial_depth_from_colour);
    out.quads = AsResults(coarse);
    return out;
  }
  ExtrinsicsResult first = std::get<ExtrinsicsResult>(std::move(fitted));
  spdlog::info(
      "depth camera from {} coarse outlines: fx {:.1f} fy {:.1f} cx {:.1f} cy {:.1f}, rms {:.2f} px, edges {:.2f} px "
      "out",
      first.views, first.depth->camera_matrix(0, 0), first.depth->camera_matrix(1, 1), first.depth->camera_matrix(0, 2),
      first.depth->camera_matrix(1, 2), first.rms_px, first.edge_offset_px);
  // Fine: every outline again where the fitted camera puts it, while that
  // finds more of them.
  int found = first.views;
  out.extrinsics = std::move(first);
  out.quads = AsResults(coarse);
  out.views = Views(frames, coarse, reading);
  for (int pass = 0; pass < kMaxFinePasses; ++pass) {
    std::vector<StageResult<DepthboardQuad>> quads(frames.size(), Rejection{"depthboard_quad", "not searched"});
    tbb::parallel_for(std::size_t{0}, frames.size(), [&](std::size_t i) {
      quads[i] = frames[i].find_outline(*out.extrinsics.depth, out.extrinsics.depth_from_colour);
    });
    std::vector<std::optional<DepthboardQuad>> fine;
    for (const auto& q : quads) fine.push_back(Accepted(q) ? std::optional(std::get<DepthboardQuad>(q)) : std::nullopt);
    // A later pass is kept only for more views than the last, and its fit can use no more than it found.
    if (pass > 0 && std::count_if(fine.begin(), fine.end(), [](const auto& q) { return q.has_value(); }) <= found)
      break;
    auto refined = RunDepthCameraFromOutlines(options, reading, board, *out.extrinsics.depth,
                                              Views(frames, fine, reading), out.extrinsics.depth_from_colour);
    if (!Accepted(refined)) break;
    const int now = std::get<ExtrinsicsResult>(refined).views;
    if (pass > 0 && now <= found) break;  // the first fine pass is kept for its narrower gates
    out.extrinsics = std::get<ExtrinsicsResult>(std::move(refined));
    out.quads = std::move(quads);
    out.views = Views(frames, fine, reading);
    found = now;
  }
  if (options.refit_for_sigmas) {
    AddJackknifeUncertainty(options, reading, board, out.views, out.extrinsics);
    AddColourCameraUncertainty(options, reading, board, colour, frames, out);
  }
  out.depth = *out.extrinsics.depth;
  out.depth.rms_reprojection_px = out.extrinsics.rms_px;
  out.depth.views = out.extrinsics.views;
  out.loosely_pinned =
      LooselyPinned(options, out.depth, "the depthboard outlines and the colour camera's own uncertainty");
  return out;
}

}  // namespace speckle
