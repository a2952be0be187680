#pragma once
// check: a depth calibration scored on a new recording of its sensor (issue
// 48). The recording's boards are paired with the calibration's own cameras
// and extrinsics, held (pipeline/steps/extrinsics_step.h, kHeld), so every
// sample's depth from its colour pose is a held-out truth for the model.
//
// The verdict, per depth band, image region and the boards' registration:
//   significant  the error's mean lies beyond 3 sigma (as rare as that:
//                Student's t), sigma combining how well this recording
//                measures it and how well the calibration's own recording
//                pinned it (for the outlines, the extrinsics' translation
//                sigma). A pose's samples share its colour pose's error, so
//                poses, not samples, are the units: the scatter of a pose's
//                mean error about its cell's, in raw units, pooled over the
//                cells, over root(poses);
//   OK           nothing significant;
//   DEGRADED     something significant, but smaller than one step of what
//                the sensor reports there: one raw unit of depth there, or
//                one depth pixel of registration;
//   RECALIBRATE  something significant and a step or more.
// Walls are shown (their flatness once corrected), not judged: a calibration
// states no sigma for a wall's flatness.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "apply/depth_calibration.h"
#include "apply/point_measure.h"
#include "pipeline/pipeline_result.h"

namespace speckle {

inline constexpr int kCheckSchemaVersion = 1;
// check's exit codes beyond the shared ones (schemas/errors.h).
inline constexpr int kExitDegraded = 10;
inline constexpr int kExitRecalibrate = 11;
inline constexpr int kExitCannotJudge = 12;

struct CheckOptions {
  std::vector<double> depth_edges_m{0.4, 0.7, 1.0, 1.3, 1.6, 2.0, 2.5, 3.0, 4.0, 6.0};
  double significance_sigmas = 3;  // the registration's, from many poses; the bands' and regions' by Student's t
  // A pose's scatter pooled over fewer degrees of freedom is too uncertain
  // to judge by; the outlines' shift is judged from this many poses.
  double min_pooled_dof = 3;
  int min_outline_poses = 4;
  int map_block_px = 20;
};

enum class CheckVerdict { kOk, kDegraded, kRecalibrate, kCannotJudge };
std::string ToString(CheckVerdict verdict);

// The depth error (model - truth) of the samples in one depth band or image region.
struct ErrorCell {
  std::string where;  // "0.70-1.00 m", "top left" (of a 3 x 3 split of the depth image)
  int samples = 0, poses = 0;
  double depth_m = 0;         // the samples' median true depth
  double mean_error_m = 0;    // mean of the poses' means
  double mean_error_raw = 0;  // the same in raw units: each error over the depth of one raw unit there
  // The depth of one raw unit there: by the calibration's model; for the
  // driver's millimetres, of one 11-bit value by the nominal relation.
  double raw_step_m = 0;
  // How well this recording measures mean_error_raw, and how well the
  // calibration's own recording pinned it (the poses its samples.h5 has
  // here; without it, taken to be like this one): the scatter of a pose's
  // mean, pooled over the cells of the kind, over root(poses), raw units.
  double standard_error_raw = 0, fitted_standard_error_raw = 0;
  int calibration_poses = 0;
  // The depth sigma the calibration states at depth_m (NaN: none): its
  // absolute accuracy, its cameras' uncertainty in it. Shown, not judged
  // by: the boards' depths here come through the same cameras, so an error
  // of theirs moves the calibration and this recording's truth alike.
  double calibration_sigma_m = 0;
  double reading_noise_m = 0;  // the samples' scatter within their poses
  double z = 0;                // mean / combined sigma (NaN: not judged)
  // Beyond this |z| is significant: 3 sigma's rarity for a pooled scatter
  // with its degrees of freedom (Student's t).
  double threshold_sigmas = 0;
  CheckVerdict verdict = CheckVerdict::kCannotJudge;
  std::string not_judged;  // why, when it was not
};

// Where the depth images show the board's outline against where the colour
// pose and the calibration's extrinsics put it (depth pixels).
struct Registration {
  int frames = 0, poses = 0;
  Eigen::Vector2d shift_px = Eigen::Vector2d::Zero();  // mean of the poses' mean corner offsets
  Eigen::Vector2d shift_standard_error_px = Eigen::Vector2d::Zero();
  double growth_px = 0;  // the outline's corners outwards, on average
  double growth_standard_error_px = 0;
  // Where the calibration puts an outline is uncertain by this: its
  // extrinsics' translation sigma, seen at the boards' median distance.
  double calibration_sigma_px = 0;
  double z = 0;  // the largest of shift u, v and growth over its combined sigma (NaN: not judged)
  CheckVerdict verdict = CheckVerdict::kCannotJudge;
  std::string not_judged;  // why, when it was not
};

struct CorrectedWall {
  int frame = 0;
  double depth_m = 0;
  int pixels = 0;
  double rms_m = 0;                  // corrected points about their plane
  double largest_region_mean_m = 0;  // of the 3 x 3 regions' mean offsets from it
  std::string largest_region;
};

struct CheckResult {
  std::vector<ErrorCell> by_depth, by_region;
  Registration registration;
  std::vector<CorrectedWall> walls;
  int board_frames = 0, paired_frames = 0, samples = 0;
  // Mean error per block of map_block_px (NaN where no sample fell).
  int map_columns = 0, map_rows = 0;
  std::vector<double> map_error_m;
  CheckVerdict verdict = CheckVerdict::kCannotJudge;
  std::vector<std::string> reasons;  // what set the verdict, worst first
  std::string judged;                // what could be judged: "2 of 4 depth bands, ..."
};

struct CheckInput {
  const apply::DepthCalibration& calibration;
  const apply::DepthSigmaTable& sigmas;
  const CameraCalibration& cameras;  // as held (with the calibration's outline rms and edge offset)
  const PipelineResult& recording;   // the graph's run on the new recording, cameras held
  const std::vector<PairedSample>* calibration_samples = nullptr;  // the calibration's own (samples.h5)
};

CheckResult CheckCalibration(const CheckInput& input, const CheckOptions& options);

}  // namespace speckle
