#include "pipeline/joint_cameras.h"

#include <spdlog/spdlog.h>

#include "lab/joint/joint_hold_out.h"
#include "pipeline/steps/depth_camera_step.h"
#include "stages/step_clock.h"

namespace speckle {

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
