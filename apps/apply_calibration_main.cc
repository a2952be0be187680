// apply-calibration [INPUT] --out DIR [--calibration VERSION] [--format ...]
// Applies a calibration to a session's frames or a fakenect dump: corrected
// point clouds (PCD, PLY, CSV) and depth images (16-bit PNG, mm), plus the
// cameras as ROS camera_info and OpenCV YAML.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <unistd.h>
#include <chrono>
#include <fstream>
#include <iostream>
#include <set>

#include "apply/depth_corrector.h"
#include "apply/registered_depth.h"
#include "apps/cli_main.h"
#include "apps/depth_sigmas.h"
#include "apps/frame_input.h"
#include "formats/camera_yaml.h"
#include "formats/csv_points.h"
#include "formats/depth_png.h"
#include "formats/depth_tiff.h"
#include "formats/export_readme.h"
#include "formats/pcd.h"
#include "formats/ply.h"
#include "formats/tf_launch.h"
#include "recorder/progress.h"
#include "recorder/recording_clock.h"
#include "schemas/artifact_schema.h"
#include "schemas/atomic_file.h"
#include "schemas/atomic_folder.h"
#include "schemas/staging.h"
#include "speckle/tool_version.h"

namespace {

using namespace speckle;
namespace fs = std::filesystem;

struct Flags {
  std::string input, out, calibration, recording;
  std::vector<std::string> formats{"pcd", "png"};
  std::string frames;  // "A:B", "A:", ":B" or "N"
  int every = 1;
  bool no_colour = false;
};

const std::set<std::string> kFormats{"pcd", "pcd-ascii", "ply", "csv", "png", "registered-png", "registered-tiff"};

struct FrameRange {
  std::int64_t begin = 0, end = -1;  // end -1: to the last frame
  bool Contains(std::int64_t i) const { return i >= begin && (end < 0 || i < end); }
};

FrameRange ParseFrames(const std::string& text) {
  FrameRange range;
  if (text.empty()) return range;
  const auto number = [&](const std::string& s) {
    std::size_t used = 0;
    long long value = -1;
    try {
      value = std::stoll(s, &used);
    } catch (const std::exception&) {
    }
    if (used != s.size() || value < 0)
      throw UsageError("--frames: expected A:B, A:, :B or N (frame indices from 0), found \"" + text + "\"");
    return static_cast<std::int64_t>(value);
  };
  const std::size_t colon = text.find(':');
  if (colon == std::string::npos) return {number(text), number(text) + 1};
  if (colon > 0) range.begin = number(text.substr(0, colon));
  if (colon + 1 < text.size()) range.end = number(text.substr(colon + 1));
  if (range.end >= 0 && range.end <= range.begin)  // it wrote an empty folder and exited 0
    throw UsageError("--frames " + text + ": selects no frame (A:B is half-open: B must exceed A)");
  return range;
}

// A range that starts past every recording's end would write an empty folder.
void RefuseRangePastEnd(const FrameRange& range, const std::string& text, const FrameInput& input) {
  std::vector<std::string> counts;
  for (const InputRecording& r : input.recordings) {
    if (range.begin < r.frame_count) return;
    counts.push_back(fmt::format("{} has {} frames", r.name, r.frame_count));
  }
  throw InputError(fmt::format("--frames {}: selects no frame ({})", text, fmt::join(counts, ", ")));
}

void WriteBytes(const fs::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out.flush()) throw WriteFailure(path, errno);
}

nlohmann::json FoldJson(const apply::FoldSummary& s) {
  return {{"knots", s.knots},
          {"raw_range", {s.raw_lo, s.raw_hi}},
          {"max_error_raw", s.max_error_raw},
          {"max_error_at", {{"u", s.worst_u}, {"v", s.worst_v}, {"raw", s.worst_raw}}},
          {"tables_used", !s.exact && s.per_pixel.empty()},
          {"folded", s.folded},
          {"per_frame", s.per_frame},
          {"per_pixel", s.per_pixel}};
}

// One frame's files; returns their names relative to the output directory.
std::vector<std::string> WriteFrame(const apply::OrganizedCloud& cloud, const apply::DepthCalibration& calibration,
                                    const std::set<std::string>& formats, const fs::path& root, const std::string& stem,
                                    const std::string& comment) {
  std::vector<std::string> files;
  const auto write = [&](const std::string& suffix, std::string_view bytes) {
    WriteBytes(root / (stem + suffix), bytes);
    files.push_back(stem + suffix);
  };
  if (formats.count("pcd")) write(".pcd", formats::PcdFile(cloud, formats::PcdEncoding::kBinary));
  if (formats.count("pcd-ascii")) write(".ascii.pcd", formats::PcdFile(cloud, formats::PcdEncoding::kAscii));
  if (formats.count("ply")) write(".ply", formats::PlyFile(cloud, comment));
  if (formats.count("csv")) write(".csv", formats::CsvPoints(cloud));
  if (formats.count("png")) {
    std::vector<float> depth(cloud.xyz.size() / 3);
    for (std::size_t p = 0; p < depth.size(); ++p) depth[p] = cloud.xyz[3 * p + 2];
    const std::vector<std::uint8_t> png = formats::DepthPngMm(depth, cloud.width, cloud.height);
    write(".png", std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
  }
  if (formats.count("registered-png") || formats.count("registered-tiff")) {
    const std::vector<float> registered = apply::RegisteredDepth(cloud, calibration);
    const int width = calibration.colour.width, height = calibration.colour.height;
    const auto image = [&](const std::vector<std::uint8_t>& bytes) {
      return std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    };
    if (formats.count("registered-png"))
      write(".registered.png", image(formats::DepthPngMm(registered, width, height)));
    if (formats.count("registered-tiff"))
      write(".registered.tiff", image(formats::DepthTiffM(registered, width, height)));
  }
  return files;
}

// Whether the frames were registered to colour: a depth-only recording (a
// libfreenect dump) or --no-colour has none to register.
std::string ColourWords(std::size_t coloured, std::size_t written) {
  if (coloured == 0) return "depth only, no colour";
  if (coloured == written) return "with colour registration";
  return fmt::format("{} of them with colour registration", coloured);
}

// applied.json before any frame: what was applied to what.
nlohmann::json AppliedJson(const Flags& flags, const std::string& source) {
  return {
      {"schema", "speckle.applied_frames"},
      {"schema_version", kAppliedFramesSchemaVersion},
      {"tool_version", kToolVersion},
      {"created_utc", UtcNowIso8601()},
      {"calibration", source},
      {"input", flags.input},
      {"formats", flags.formats},
      {"cameras", {"depth_camera_info.yaml", "rgb_camera_info.yaml", "cameras_opencv.yml", "depth_to_rgb_tf.launch"}},
      {"frames", nlohmann::json::array()},
      {"skipped_frames", nlohmann::json::array()}};
}

// Applies the calibration to every chosen frame of `input`, writing each
// frame's files into `staging`; adds the frames, the skipped ones and the
// fold to `applied`.
void ApplyFrames(const Flags& flags, const FrameRange& range, FrameInput& input,
                 const apply::DepthCalibration& calibration, const fs::path& staging, nlohmann::json& applied) {
  const std::string source = calibration.file.string();
  const bool colour = !flags.no_colour;
  const apply::DepthCorrector corrector(calibration);
  // Tables that miss their tolerance are not used: said, since every frame is then slower.
  if (const std::string note = apply::FoldNote(corrector.Summary()); !note.empty()) spdlog::warn("{}", note);
  applied["fold"] = FoldJson(corrector.Summary());
  const std::set<std::string> formats(flags.formats.begin(), flags.formats.end());
  std::int64_t total = 0;
  for (const InputRecording& r : input.recordings) total += r.frame_count;
  Progress progress("apply-calibration: frames", total);
  std::int64_t done = 0;
  double apply_seconds = 0;
  for (InputRecording& r : input.recordings) {
    fs::create_directories(staging / r.name);
    RecordingClock clock(input.clock_origin_ns);
    std::int64_t index = 0;
    for (auto pair = r.frames->Next(); pair; pair = r.frames->Next(), ++index) {
      progress.Update(++done);
      const double time_s = clock.Seconds(*pair);
      if (!range.Contains(index) || (index - range.begin) % flags.every != 0) continue;
      if (!pair->depth.valid()) {
        spdlog::warn("{} frame {}: no depth frame, skipped", r.path.string(), index);
        applied["skipped_frames"].push_back({{"recording", r.name}, {"index", index}, {"reason", "no depth frame"}});
        continue;
      }
      const cv::Mat& raw = pair->depth.image;
      const cv::Mat rgb = colour && pair->colour.valid() ? pair->colour.image : cv::Mat();
      const auto start = std::chrono::steady_clock::now();
      const apply::OrganizedCloud cloud =
          corrector.Cloud({raw.ptr<std::uint16_t>(), raw.total()}, time_s, {rgb.data, rgb.total() * rgb.elemSize()});
      apply_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const std::string stem = fmt::format("{}/{:06}", r.name, index);
      std::size_t points = 0;
      for (std::size_t p = 0; p < cloud.xyz.size(); p += 3) points += std::isfinite(cloud.xyz[p + 2]);
      applied["frames"].push_back({{"recording", r.name},
                                   {"index", index},
                                   {"time_s", time_s},
                                   {"points", points},
                                   {"colour", !cloud.rgb.empty()},
                                   {"files", WriteFrame(cloud, calibration, formats, staging, stem,
                                                        "Speckle apply-calibration of " + source)}});
    }
  }
  progress.Finish();
  const std::size_t written = applied["frames"].size();
  applied["apply_ms_per_frame"] = written ? 1e3 * apply_seconds / static_cast<double>(written) : 0.0;
  std::size_t coloured = 0;
  for (const auto& frame : applied["frames"]) coloured += frame["colour"].get<bool>();
  spdlog::info("{} frames applied ({:.2f} ms a frame, {}), {} skipped", written,
               written ? 1e3 * apply_seconds / static_cast<double>(written) : 0.0, ColourWords(coloured, written),
               applied["skipped_frames"].size());
}

int Run(const Flags& flags) {
  const fs::path out = NormalizeOutPath(flags.out, "--out");
  RemoveStaleStaging(fs::absolute(out).parent_path());
  if (fs::exists(out))
    throw InputError(out.string() + ": exists; apply-calibration overwrites nothing, choose a new --out");
  for (const std::string& f : flags.formats)
    if (!kFormats.count(f))
      throw UsageError(fmt::format("--format: unknown \"{}\", expected one of {}", f, fmt::join(kFormats, ", ")));
  if (flags.every < 1) throw UsageError("--every: expected 1 or more");
  const FrameRange range = ParseFrames(flags.frames);
  std::optional<FrameInput> input;
  if (!flags.input.empty()) input = OpenFrameInput(flags.input, flags.recording);
  if (!input && flags.calibration.empty())
    throw UsageError("give an INPUT to apply the calibration to, or --calibration to export its cameras");
  const fs::path calibration_path =
      input ? ChooseCalibration(flags.calibration, *input) : CalibrationFile(flags.calibration);
  const apply::DepthCalibration calibration = apply::LoadDepthCalibration(calibration_path);
  const bool colour = !flags.no_colour;
  if (input)
    for (const InputRecording& r : input->recordings) CheckMatchesCalibration(r, calibration, colour);
  if (input && !flags.frames.empty()) RefuseRangePastEnd(range, flags.frames, *input);

  // Everything goes to a staging folder beside --out, renamed when complete.
  WriteFolderAside(
      PartialPathFor(fs::absolute(out)),
      [&](const fs::path& staging) {
        const std::string source = calibration.file.string();
        WriteBytes(staging / "depth_camera_info.yaml", formats::RosCameraInfoYaml(calibration.depth, "depth", source));
        WriteBytes(staging / "rgb_camera_info.yaml", formats::RosCameraInfoYaml(calibration.colour, "rgb", source));
        WriteBytes(staging / "cameras_opencv.yml", formats::OpenCvCalibrationYaml(calibration, source));
        WriteBytes(staging / "depth_to_rgb_tf.launch", formats::StaticTransformLaunch(calibration, source));
        WriteBytes(staging / "README.txt",
                   formats::ExportReadme(calibration, source, {flags.formats.begin(), flags.formats.end()},
                                         input.has_value()));
        nlohmann::json applied = AppliedJson(flags, source);
        if (input) ApplyFrames(flags, range, *input, calibration, staging, applied);
        WriteBytes(staging / "applied.json", applied.dump(2) + "\n");
      },
      [&](const fs::path& staging) { return RenameInto(staging, out); });
  std::cout << out.string() << "\n";
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Apply a depth calibration to recorded frames: corrected point clouds and depth images without resampling,\n"
      "and the cameras as ROS camera_info and OpenCV YAML. Writes a new directory --out and prints its path."};
  Flags flags;
  app.add_option("INPUT", flags.input, "session directory or fakenect:DUMP_DIR (none: export the cameras only)");
  app.add_option("--out", flags.out, "output directory to create (must not exist)")->required();
  app.add_option(
      "--calibration", flags.calibration,
      "a session (its newest version), a version directory or its calibration.json (default: INPUT's newest)");
  app.add_option("--recording", flags.recording, "only this recording of the session, e.g. planar");
  app.add_option("--format", flags.formats,
                 "pcd (binary), pcd-ascii, ply, csv, png (16-bit depth, mm), registered-png (depth registered to the "
                 "colour camera, 16-bit mm), registered-tiff (the same, 32-bit float metres)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--frames", flags.frames, "frame indices A:B (half-open), A:, :B or N, in each recording");
  app.add_option("--every", flags.every, "every Nth frame of the range")->capture_default_str();
  app.add_flag("--no-colour", flags.no_colour, "do not register colour onto the points");
  return RunCli("apply-calibration", app, argc, argv, [&] { return Run(flags); });
}
