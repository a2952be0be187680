// measure INPUT --frame N --from U,V --to U,V: the 3-D distance between the
// points of two pixels of a corrected frame (the thesis's measuring tool).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "apply/point_measure.h"
#include "apps/cli_main.h"
#include "apps/depth_sigmas.h"
#include "apps/frame_input.h"
#include "recorder/recording_clock.h"
#include "schemas/artifact_schema.h"

namespace {

using namespace speckle;

struct Flags {
  std::string input, calibration, recording;
  std::int64_t frame = 0;
  std::vector<int> from, to;
  int window = 0;
  bool json = false;
};

nlohmann::json PointJson(const apply::PixelPoint& p) {
  return {{"pixel", {p.u, p.v}}, {"xyz_m", {p.xyz.x(), p.xyz.y(), p.xyz.z()}}, {"points_used", p.points_used}};
}

// "± 1.2 mm (the calibration's; ...)", or why there is no sigma.
std::string SigmaText(const apply::Measurement& m, const apply::DepthSigmaTable& table) {
  if (table.depth_m.empty()) return " (no ±: the calibration's report.json states no depth sigma)";
  const bool covered = table.Covers(m.from.xyz.z()) && table.Covers(m.to.xyz.z());
  return fmt::format(
      " ± {:.1f} mm (the calibration's depth sigma at both ends{}; the sensor's noise at the two pixels "
      "is not in it: widen --window to tame it)",
      1000 * apply::DistanceSigma(m, table),
      covered ? ""
              : fmt::format(", beyond its {:.2f}-{:.2f} m taken at the end rows' share", table.depth_m.front(),
                            table.depth_m.back()));
}

int Run(const Flags& flags) {
  FrameInput input = OpenFrameInput(flags.input, flags.recording);
  InputRecording& recording = input.recordings.front();
  const apply::DepthCalibration calibration = apply::LoadDepthCalibration(ChooseCalibration(flags.calibration, input));
  CheckMatchesCalibration(recording, calibration, false);
  RecordingClock clock(input.clock_origin_ns);
  std::optional<FramePair> pair;
  for (std::int64_t index = 0; index <= flags.frame; ++index) {
    pair = recording.frames->Next();
    if (!pair) {
      throw InputError(
          fmt::format("{}: --frame {}: the recording has {} frames", recording.path.string(), flags.frame, index));
    }
    clock.Seconds(*pair);
  }
  if (!pair->depth.valid())
    throw InputError(fmt::format("{} frame {}: no depth frame", recording.path.string(), flags.frame));
  const apply::DepthCorrector corrector(calibration);
  if (const std::string note = apply::FoldNote(corrector.Summary()); !note.empty()) spdlog::info("{}", note);
  const cv::Mat& raw = pair->depth.image;
  const apply::OrganizedCloud cloud = corrector.Cloud({raw.ptr<std::uint16_t>(), raw.total()}, clock.Seconds(*pair));
  const apply::Measurement m =
      apply::Measure(cloud, flags.from[0], flags.from[1], flags.to[0], flags.to[1], flags.window);
  const apply::DepthSigmaTable sigmas = DepthSigmasOf(calibration.file);
  const auto distance_sigma =
      sigmas.depth_m.empty() ? nlohmann::json(nullptr) : nlohmann::json(apply::DistanceSigma(m, sigmas));
  if (flags.json) {
    std::cout << nlohmann::json{{"recording", recording.path.string()},
                                {"frame", flags.frame},
                                {"calibration", calibration.file.string()},
                                {"window", flags.window},
                                {"from", PointJson(m.from)},
                                {"to", PointJson(m.to)},
                                {"displacement_m", {m.displacement.x(), m.displacement.y(), m.displacement.z()}},
                                {"distance_m", m.distance_m},
                                {"distance_sigma_m", distance_sigma}}
                     .dump(2)
              << "\n";
    return kExitOk;
  }
  const auto line = [](const char* name, const apply::PixelPoint& p) {
    return fmt::format("{:<13}({}, {}) -> ({:+.4f}, {:+.4f}, {:+.4f}) m  [{} points]\n", name, p.u, p.v, p.xyz.x(),
                       p.xyz.y(), p.xyz.z(), p.points_used);
  };
  std::cout << fmt::format("{} frame {} with {}\n", recording.path.string(), flags.frame, calibration.file.string())
            << line("from", m.from) << line("to", m.to)
            << fmt::format("displacement ({:+.4f}, {:+.4f}, {:+.4f}) m\ndistance     {:.4f} m{}\n", m.displacement.x(),
                           m.displacement.y(), m.displacement.z(), m.distance_m, SigmaText(m, sigmas));
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Measure the 3-D distance and displacement between the points of two pixels of a corrected depth frame."};
  Flags flags;
  app.add_option("INPUT", flags.input, "session directory or fakenect:DUMP_DIR")->required();
  app.add_option("--frame", flags.frame, "frame index in the recording")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](const std::string& text) { return text.starts_with('-') ? "a frame index is 0 or more" : ""; },
          "0 or more"));
  app.add_option("--from", flags.from, "first pixel U,V (depth image)")->required()->delimiter(',')->expected(2);
  app.add_option("--to", flags.to, "second pixel U,V")->required()->delimiter(',')->expected(2);
  app.add_option("--window", flags.window, "median of the points within this many pixels (tames noise)")
      ->capture_default_str()
      ->check(CLI::Range(0, 50));
  app.add_option(
      "--calibration", flags.calibration,
      "a session (its newest version), a version directory or its calibration.json (default: INPUT's newest)");
  app.add_option("--recording", flags.recording, "the session's recording (default: the first with depth)");
  app.add_flag("--json", flags.json, "print the measurement as JSON");
  return RunCli("measure", app, argc, argv, [&] { return Run(flags); });
}
