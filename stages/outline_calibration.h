#pragma once
// The colour -> depth extrinsics, and for sessions without IR images the
// depth camera itself, from the board's outline: each pose's outline
// corners, known in the colour camera from its chessboard pose, against the
// corners of the depthboard quad found in the depth image (thesis ch. 3).
//
// Real recordings rarely hold IR images of the chessboard, and a real
// Kinect's IR camera sits pixels and percent away from the nominal 580 px
// camera: with the nominal camera the extrinsics bend to absorb the focal
// length, every true depth moves by centimetres and the outline gates miss
// the board. The outline corners of poses spread in depth and across the
// image pin the focal lengths (the corners' spread in pixels against their
// depth), the principal point and the low radial terms, jointly with the
// extrinsics (Herrera et al. fit the depth camera from the depth data too).
#include <optional>
#include <string>
#include <vector>

#include "stages/records.h"

namespace speckle {

// One board pose seen by both cameras: the colour pose and the depth quad.
struct ExtrinsicsView {
  Eigen::Isometry3d colour_from_board;
  DepthboardQuad quad;
  Eigen::Vector3d board_velocity = Eigen::Vector3d::Zero();  // colour-camera m/s (see FrameWork)
  // Board pixels (u, v, raw) inside the outline, for the depth camera's fit:
  // their raw values against the board's plane pin the rotation that four
  // corners a view trade against the principal point.
  std::vector<Eigen::Vector3d> board_pixels;
};

struct ExtrinsicsOptions {
  double outlier_px = 3.0;  // views whose outline reprojects worse are dropped after a first fit
  // The depth image's delay after the colour image is fitted with the
  // extrinsics when the views' median board speed reaches this: a moving
  // board's depth outline lags its colour pose, which a rotation would
  // otherwise absorb.
  double min_speed_for_delay_m_s = 0.05;
  // Fitting the depth camera too needs at least this many views: 4 corners a
  // view against 4 intrinsics, 2 radial terms and 6 extrinsic parameters.
  int min_views_for_intrinsics = 6;
  // Board-plane pixels in the depth camera's fit: each raw value against the
  // reciprocal base form of its depth on the board's plane (Herrera et al.),
  // scaled by this raw noise and down-weighted by Huber beyond it.
  double plane_raw_sigma = 1.0;
  double outline_corner_sigma_px = 0.3;  // the quads' corners, sub-pixel from line fits
  int jackknife_groups = 10;
  // The jackknife's refits and the colour camera's perturbation add to the
  // covariance's standard deviations. Off when the joint calibration refines
  // the cameras and states their uncertainty from every observation: they
  // were half of the outline step (run-pipeline --joint-cameras, which runs
  // again with them when the joint fit is refused).
  bool refit_for_sigmas = true;
  // A depth camera fitted less surely than this is said to be loosely pinned
  // (the run goes on with it, and says what to record).
  double max_focal_sigma_share = 0.01;
  double max_principal_point_sigma_px = 5;  // refits, each without a tenth of the views, for the camera's uncertainty
  double plane_huber = 3.0;                 // in sigmas
  // An IR chessboard's calibration of the depth camera, when the session has
  // one: the outline fit then refines it jointly with the extrinsics from
  // the outline corners (not the board planes), each intrinsic held to it by
  // a Gaussian prior of its standard deviation (a term calibrated with none,
  // such as a fixed k3, is held where it is).
  std::optional<CameraIntrinsics> depth_prior;
  // False, naming the first broken rule's field in *why (schemas/option_check.h).
  bool IsValid(std::string* why) const;
};

// depth_from_colour minimising the reprojection of the board's outline corners
// (from each colour pose) onto the depth quads, over all views (Ceres).
struct ExtrinsicsResult {
  Eigen::Isometry3d depth_from_colour = Eigen::Isometry3d::Identity();
  double rms_px = 0;
  int views = 0;
  // Standard deviation of the translation (metres), from the fit's covariance
  // scaled by its residual variance.
  Eigen::Vector3d translation_sigma_m = Eigen::Vector3d::Zero();
  std::optional<double> delay_s;  // fitted when the board moved (see ExtrinsicsOptions)
  // The depth camera, when it was fitted (fx, fy, cx, cy, k1, k2 free; their
  // standard deviations in `stddev`, zero for the terms held).
  std::optional<CameraIntrinsics> depth;
  std::vector<bool> used;  // which views the final fit kept
  // How far outside the board's edge the depth step lies (px), fitted with
  // the extrinsics: a structured-light sensor's edges are displaced by its
  // matching window and by where the outline's line fits put them, and the
  // extrinsics' depth offset would otherwise absorb it (0.05 px outwards
  // reads as 0.6 mm nearer at 1 m for this board).
  double edge_offset_px = 0;
};

// `reading` is the recording's depth units: a millimetre recording's board
// planes take the linear_mm form, their sigma in millimetres per raw step.
// With `depth` held fixed.
ExtrinsicsResult RunExtrinsicsCalibration(const ExtrinsicsOptions& options, const DepthReading& reading,
                                          const BoardGeometry& board, const CameraIntrinsics& depth,
                                          const std::vector<ExtrinsicsView>& views, const Eigen::Isometry3d& initial);

// The depth camera fitted with the extrinsics, from `prior` (its p1, p2 and
// k3 are held). Rejects when there are too few views, or when the fit fails.
StageResult<ExtrinsicsResult> RunDepthCameraFromOutlines(const ExtrinsicsOptions& options, const DepthReading& reading,
                                                         const BoardGeometry& board, const CameraIntrinsics& prior,
                                                         const std::vector<ExtrinsicsView>& views,
                                                         const Eigen::Isometry3d& initial);

// The depth camera and extrinsics fitted again to other views (or the same
// views with other colour poses), from the fit `from`: one round, no covariance.
std::optional<ExtrinsicsResult> RefitDepthCamera(const ExtrinsicsOptions& options, const DepthReading& reading,
                                                 const BoardGeometry& board, const std::vector<ExtrinsicsView>& views,
                                                 const ExtrinsicsResult& from);

// What a depth camera fit gives with a standard deviation, by index: the
// intrinsics in the order of CameraIntrinsics::stddev (fx, fy, cx, cy, k1, k2,
// p1, p2, k3), then the extrinsics' translation x, y, z (metres).
inline constexpr int kFittedValues = 12;
double FittedValue(const ExtrinsicsResult& fit, int i);
double& FittedSigma(ExtrinsicsResult& fit, int i);

// Widens a fitted depth camera's and its translation's standard deviations
// to those of a delete-a-group jackknife over the views
// (options.jackknife_groups refits): the covariance counts every board pixel
// as independent, but a pose's pixels share its colour pose's error.
void AddJackknifeUncertainty(const ExtrinsicsOptions& options, const DepthReading& reading, const BoardGeometry& board,
                             const std::vector<ExtrinsicsView>& views, ExtrinsicsResult& result);

// How a quad corner moves when both its sides move outwards by one pixel:
// (n1 + n2) / (1 + n1 . n2), n1 and n2 the sides' outward normals (the
// edge offset's direction at that corner).
Eigen::Vector2d CornerOutward(const DepthboardQuad& quad, int corner);

// The board's outline corners (0,0), (W,0), (W,H), (0,H) in board coordinates.
std::array<Eigen::Vector3d, 4> OutlineCorners(const BoardGeometry& board);

// RMS distance (px) of a view's four outline corners from where `depth` and
// the fit (its extrinsics, delay and edge offset) put them.
double OutlineErrorPx(const BoardGeometry& board, const CameraIntrinsics& depth, const ExtrinsicsResult& fit,
                      const ExtrinsicsView& view);

}  // namespace speckle
