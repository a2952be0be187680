#include "pipeline/joint_cameras.h"

#include <spdlog/spdlog.h>

#include "lab/joint/joint_hold_out.h"
#include "pipeline/steps/depth_camera_step.h"
#include "stages/step_clock.h"

namespace speckle {
namespace {

std::array<double, 4> FocalAndPrincipalPoint(const CameraIntrinsics& c) {
  const cv::Matx33d& m = c.camera_matrix;
  return {m(0, 0), m(1, 1), m(0, 2), m(1, 2)};
}

// Where the joint calibration took a camera the session gave with sigmas
// (its first `terms` of fx, fy, cx, cy: a depth camera's principal point is
// the depth image's own, see SayDepthImageShift).
void SayPrior(const std::optional<CameraIntrinsics>& prior, const CameraIntrinsics& fitted, const char* camera,
              std::size_t terms) {
  if (!prior) return;
  static const char* kNames[4] = {"fx", "fy", "cx", "cy"};
  const auto k = FocalAndPrincipalPoint;
  std::string moved, far;
  for (std::size_t i = 0; i < terms; ++i) {
    if (!(prior->stddev[i] > 0)) continue;
    const double shift = (k(fitted)[i] - k(*prior)[i]) / prior->stddev[i];
    moved += fmt::format("{}{} {:.2f} ± {:.2f} -> {:.2f} ± {:.2f}", moved.empty() ? "" : ", ", kNames[i], k(*prior)[i],
                         prior->stddev[i], k(fitted)[i], fitted.stddev[i]);
    if (std::abs(shift) > 3) far += fmt::format("{}{} by {:.1f} sigma", far.empty() ? "" : ", ", kNames[i], shift);
  }
  spdlog::info("{} camera: the session's, refined within its stated sigmas{}{}", camera, moved.empty() ? "" : ": ",
               moved);
  if (!far.empty())
    spdlog::warn(
        "{} camera: this session moved it beyond 3 of the sigmas session.json states ({}): the camera "
        "given may not be this sensor's, or its sigmas are too small",
        camera, far);
}

// The depth image's principal point against the depth camera the session
// gave, which is the IR image's: the depth image's shift from the IR image
// (ROS kinect_calibration measures a few pixels), or an error in the camera
// given; the depth samples cannot tell which (model/effects/depth_grid_offset.h).
void SayDepthImageShift(const CameraCalibration& start, const CameraIntrinsics& fitted) {
  if (start.depth_intrinsics_source != "session") return;
  const auto given = FocalAndPrincipalPoint(start.depth), at = FocalAndPrincipalPoint(fitted);
  const double du = at[2] - given[2], dv = at[3] - given[3], su = fitted.stddev[2], sv = fitted.stddev[3];
  const bool shifted = std::abs(du) > 3 * su || std::abs(dv) > 3 * sv;
  spdlog::info(
      "depth image: its principal point is {:+.2f} ± {:.2f} px, {:+.2f} ± {:.2f} px from the given depth camera's{}",
      du, su, dv, sv,
      shifted ? " (beyond 3 sigma): the depth image's shift from the IR image, or an error in the camera given"
              : ", within 3 sigma of it");
}

// The depth camera's terms an effect trades with, and what separates them.
std::string Trades(const JointAccount& joint) {
  return fmt::format(
      "{}: the effect and the depth camera trade (board outlines in the depth image, or an IR chessboard recording, "
      "would tell them apart)",
      fmt::join(joint.trades, ", "));
}

}  // namespace

std::optional<JointCameras> FitCamerasJointly(const JointCamerasInput& in) {
  const StepClock clock;
  RawRateOptions at_pixel = in.raw_rate;
  at_pixel.at_fixed_pixel = true;
  std::vector<PairedSample> samples = AssignRawRates(at_pixel, in.samples);
  auto fitted = joint::RunJointCalibration(
      in.options, {in.board, in.start, in.spec.base_form, in.reading, in.frames, samples, in.spec.effects});
  if (!Accepted(fitted)) {
    spdlog::warn("joint calibration not fitted ({}); {} cameras are kept", std::get<Rejection>(fitted).reason, in.kept);
    return std::nullopt;
  }
  auto& j = std::get<joint::JointCalibration>(fitted);
  const auto& c = j.cameras;
  const auto& terms = c.joint->terms;
  spdlog::info(
      "joint calibration of {}{} ({:.1f} s, {} iterations): colour fx {:.2f} ± {:.2f}, depth fx {:.2f} ± {:.2f} "
      "cx {:.2f} ± {:.2f} cy {:.2f} ± {:.2f}; scatter {} colour, {} outline, {} depth",
      in.spec.Definition().Describe(), in.again, clock.Seconds(), c.joint->iterations, c.colour.camera_matrix(0, 0),
      c.colour.stddev[0], c.depth.camera_matrix(0, 0), c.depth.stddev[0], c.depth.camera_matrix(0, 2),
      c.depth.stddev[2], c.depth.camera_matrix(1, 2), c.depth.stddev[3], terms[0].Scatter(), terms[1].Scatter(),
      terms[2].Scatter());
  SayPrior(c.colour_prior, c.colour, "colour", 4);
  SayPrior(c.depth_prior, c.depth, "depth", 2);
  SayDepthImageShift(in.start, c.depth);
  JointCameras out{j.cameras, std::move(samples), {}, {}};
  // The outlines' or board planes' warning was about the start; the joint camera is judged anew.
  if (out.cameras.depth_intrinsics_source == "depth_outlines" ||
      out.cameras.depth_intrinsics_source == "joint_board_planes") {
    auto loose = LooselyPinned(in.extrinsics, out.cameras.depth, "the joint calibration");
    if (loose && !c.joint->trades.empty()) *loose += "; " + Trades(*c.joint);
    out.cameras.depth_intrinsics_warning = loose.value_or("");
    if (loose) spdlog::warn("{}", *loose);
  }
  if (!c.joint->trades.empty() && out.cameras.depth_intrinsics_warning.empty())
    spdlog::info("joint calibration: {}", Trades(*c.joint));
  joint::MoveSamples(j, out.samples);
  out.perturbations.depths = std::move(j.perturbations);
  out.perturbations.in_floor = 0;
  out.judge = joint::MakeJointJudge({in.options, in.board, out.cameras, in.reading, in.frames, in.folds});
  return out;
}

}  // namespace speckle
