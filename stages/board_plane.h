#pragma once
// Board-plane pairing, for rigs whose board is larger than its printed
// chessboard (Herrera's and Xiang's toolbox data): the outline is not at the
// chessboard's edge, so instead every valid depth pixel of the board is
// paired with the board's plane as the colour camera sees it, and the depth
// intrinsics, the colour -> depth extrinsics and the depth model are
// estimated together in one Ceres problem (Herrera et al., TPAMI 2012).
#include <string>
#include <vector>

#include "model/base_form.h"
#include "stages/records.h"

namespace speckle {

struct BoardRegionOptions {
  double margin_squares = 2.0;  // the board extends past the chessboard by up to this
  double max_step_raw = 6;      // neighbouring board pixels differ by less
  int erode_px = 4;             // keep away from the board's edge (mixed pixels)
  int stride = 3;               // every stride-th pixel is enough
  int min_pixels = 100;
  // False, naming the first broken rule's field in *why (schemas/option_check.h).
  bool IsValid(std::string* why) const;
};

// Board pixels (u, v, raw) of one depth frame, found by growing the board
// from where the colour pose puts the chessboard.
struct BoardRegion {
  std::vector<Eigen::Vector3d> pixels;
};

StageResult<BoardRegion> RunBoardRegion(const BoardRegionOptions& options, const cv::Mat& raw,
                                        const DepthReading& reading,
                                        const std::array<Eigen::Vector2d, 4>& chessboard_outline_px, double square_px);

struct PlaneObservation {
  int frame = 0, pose = 0;
  double time_s = 0;
  Eigen::Isometry3d colour_from_board;
  BoardRegion region;
};

struct JointPlaneOptions {
  model::BaseForm form = model::BaseForm::kReciprocal;
  double huber_raw = 3;  // board regions may catch a few background pixels
  int max_iterations = 100;
  int jackknife_groups = 8;  // refits, each without an eighth of the poses, for the intrinsics' uncertainty
  // False, naming the first broken rule's field in *why (schemas/option_check.h).
  bool IsValid(std::string* why) const;
};

struct JointPlaneResult {
  CameraIntrinsics depth;  // fx, fy, cx, cy fitted; no distortion
  Eigen::Isometry3d depth_from_colour = Eigen::Isometry3d::Identity();
  std::vector<double> depth_parameters;
  Eigen::Vector3d translation_sigma_m = Eigen::Vector3d::Zero();  // of depth_from_colour; 0: not determined
  // The jackknife's refits (depth and depth_from_colour only), for the
  // samples' depth perturbations.
  std::vector<std::pair<CameraIntrinsics, Eigen::Isometry3d>> jackknife_refits;
  double rms_raw = 0;
  int pixels = 0;
  std::string solver_report;
};

StageResult<JointPlaneResult> RunJointPlaneCalibration(const JointPlaneOptions& options,
                                                       const std::vector<PlaneObservation>& observations,
                                                       const CameraIntrinsics& initial_depth,
                                                       const Eigen::Isometry3d& initial_depth_from_colour);

// Standard deviations of the jointly fitted fx, fy, cx, cy (into
// result.depth.stddev) and extrinsics translation (result.translation_sigma_m) by a delete-a-group jackknife over the
// poses, each group refitted from the joint solution: the board's pixels share their pose's error, so a covariance over
// pixels would claim far too much.
void AddJointPlaneUncertainty(const JointPlaneOptions& options, const std::vector<PlaneObservation>& observations,
                              JointPlaneResult& result);

// How the jackknife's spread moves every sample's true depth: per principal
// direction of the refits' depths (those holding at least 1 % of the
// spread), observations' samples in order, one standard deviation along it.
// The intrinsics and extrinsics move together, as the board planes allow,
// where moving one of them by its own sigma would count what the others
// take back. Empty without refits.
std::vector<std::vector<double>> JointPlanePerturbations(const std::vector<PlaneObservation>& observations,
                                                         const JointPlaneResult& result);

// The paired samples the joint solution implies: each board pixel's raw
// value with the depth where its ray meets the board's plane.
std::vector<PairedSample> PlaneSamples(const std::vector<PlaneObservation>& observations, const CameraIntrinsics& depth,
                                       const Eigen::Isometry3d& depth_from_colour);

}  // namespace speckle
