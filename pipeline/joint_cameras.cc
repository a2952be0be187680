#include "pipeline/joint_cameras.h"

#include <spdlog/spdlog.h>

#include "lab/joint/joint_hold_out.h"
#include "pipeline/steps/depth_camera_step.h"
#include "stages/step_clock.h"

namespace speckle {
namespace {

// Where the joint calibration took a camera the session gave with sigmas.
void SayPrior(const std::optional<CameraIntrinsics>& prior, const CameraIntrinsics& fitted, const char* camera) {
  if (!prior) return;
  static const char* kNames[4] = {"fx", "fy", "cx", "cy"};
  const auto k = [](const CameraIntrinsics& c) {
    const cv::Matx33d& m = c.camera_matrix;
    return std::array<double, 4>{m(0, 0), m(1, 1), m(0, 2), m(1, 2)};
  };
  std::string moved, far;
  for (std::size_t i = 0; i < 4; ++i) {
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
  SayPrior(c.colour_prior, c.colour, "colour");
  SayPrior(c.depth_prior, c.depth, "depth");
  JointCameras out{j.cameras, std::move(samples), {}, {}};
  // The outlines' or board planes' warning was about the start; the joint camera is judged anew.
  if (out.cameras.depth_intrinsics_source == "depth_outlines" ||
      out.cameras.depth_intrinsics_source == "joint_board_planes") {
    const auto loose = LooselyPinned(in.extrinsics, out.cameras.depth, "the joint calibration");
    out.cameras.depth_intrinsics_warning = loose.value_or("");
    if (loose) spdlog::warn("{}", *loose);
  }
  joint::MoveSamples(j, out.samples);
  out.perturbations.depths = std::move(j.perturbations);
  out.perturbations.in_floor = 0;
  out.judge = joint::MakeJointJudge({in.options, in.board, out.cameras, in.reading, in.frames, in.folds});
  return out;
}

}  // namespace speckle
