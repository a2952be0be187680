#include "apps/check_report.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "apps/map_legend.h"
#include "schemas/atomic_file.h"
#include "schemas/atomic_folder.h"
#include "schemas/errors.h"
#include "schemas/html_text.h"
#include "schemas/staging.h"
#include "speckle/tool_version.h"

namespace speckle {
namespace {

namespace fs = std::filesystem;

constexpr double kMapFullScaleM = 5e-3;  // the error map's full colour

nlohmann::json Number(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

nlohmann::json ToJson(const ErrorCell& c) {
  return {{"where", c.where},
          {"samples", c.samples},
          {"poses", c.poses},
          {"depth_m", Number(c.depth_m)},
          {"mean_error_mm", Number(1e3 * c.mean_error_m)},
          {"mean_error_raw", Number(c.mean_error_raw)},
          {"standard_error_raw", Number(c.standard_error_raw)},
          {"fitted_standard_error_raw", Number(c.fitted_standard_error_raw)},
          {"calibration_poses", c.calibration_poses},
          {"calibration_sigma_mm", Number(1e3 * c.calibration_sigma_m)},
          {"raw_step_mm", Number(1e3 * c.raw_step_m)},
          {"reading_noise_mm", Number(1e3 * c.reading_noise_m)},
          {"sigmas", Number(c.z)},
          {"threshold_sigmas", Number(c.threshold_sigmas)},
          {"verdict", ToString(c.verdict)},
          {"not_judged", c.not_judged}};
}

nlohmann::json ToJson(const Registration& r) {
  return {{"frames", r.frames},
          {"poses", r.poses},
          {"shift_px", {Number(r.shift_px.x()), Number(r.shift_px.y())}},
          {"shift_standard_error_px", {Number(r.shift_standard_error_px.x()), Number(r.shift_standard_error_px.y())}},
          {"growth_px", Number(r.growth_px)},
          {"growth_standard_error_px", Number(r.growth_standard_error_px)},
          {"calibration_sigma_px", Number(r.calibration_sigma_px)},
          {"sigmas", Number(r.z)},
          {"verdict", ToString(r.verdict)}};
}

// Blue nearer than the truth, white on it, red farther; full colour at 5 mm.
cv::Vec3b ErrorColour(double error_m) {
  const double t = std::clamp(error_m / kMapFullScaleM, -1.0, 1.0);
  const auto fade = static_cast<uchar>(255 * (1 - std::abs(t)));
  return t > 0 ? cv::Vec3b(fade, fade, 255) : cv::Vec3b(255, fade, fade);
}

// Depth error over the image as a diverging map, black where no board was, with its legend.
void WriteMap(const CheckResult& r, const fs::path& file) {
  cv::Mat small(r.map_rows, r.map_columns, CV_8UC3, cv::Scalar(0, 0, 0));
  for (int row = 0; row < r.map_rows; ++row)
    for (int column = 0; column < r.map_columns; ++column) {
      const double e = r.map_error_m[static_cast<std::size_t>(row * r.map_columns + column)];
      if (std::isfinite(e)) small.at<cv::Vec3b>(row, column) = ErrorColour(e);
    }
  cv::Mat big;
  const int scale = std::max(8, (480 + r.map_columns - 1) / std::max(1, r.map_columns));  // the legend's width
  cv::resize(small, big, cv::Size(), scale, scale, cv::INTER_NEAREST);
  MapLegend legend{cv::Mat(1, 101, CV_8UC3), "-5 mm (nearer)", "0", "+5 mm (farther)",
                   "depth error, calibration minus board; black: no board there"};
  for (int i = 0; i <= 100; ++i) legend.bar.at<cv::Vec3b>(0, i) = ErrorColour(kMapFullScaleM * (i - 50) / 50.0);
  errno = 0;
  if (!cv::imwrite(file.string(), WithLegend(big, legend))) throw WriteFailure(file, errno);
}

std::string Cell(const nlohmann::json& v) {
  if (v.is_null()) return "–";
  if (v.is_number_float()) return fmt::format("{:.2f}", v.get<double>());
  if (v.is_string()) return HtmlEscape(v.get<std::string>());
  return HtmlEscape(v.dump());
}

std::string Table(const nlohmann::json& rows) {
  static const char* kColumns[] = {"where",
                                   "samples",
                                   "poses",
                                   "mean_error_raw",
                                   "standard_error_raw",
                                   "fitted_standard_error_raw",
                                   "mean_error_mm",
                                   "raw_step_mm",
                                   "sigmas",
                                   "threshold_sigmas",
                                   "verdict",
                                   "not_judged"};
  std::string html = "<table><tr>";
  for (const char* c : kColumns) html += fmt::format("<th>{}</th>", c);
  html += "</tr>\n";
  for (const auto& row : rows) {
    html += "<tr>";
    for (const char* c : kColumns) html += "<td>" + Cell(row[c]) + "</td>";
    html += "</tr>\n";
  }
  return html + "</table>\n";
}

}  // namespace

nlohmann::json ToJson(const CheckArtifact& a) {
  const CheckResult& r = a.result;
  nlohmann::json j = {{"schema", "speckle.check"},
                      {"schema_version", kCheckSchemaVersion},
                      {"tool_version", kToolVersion},
                      {"created_utc", UtcNowIso8601()},
                      {"calibration", a.calibration_file.string()},
                      {"recording", a.recording},
                      {"verdict", ToString(r.verdict)},
                      {"reasons", r.reasons},
                      {"board_frames", r.board_frames},
                      {"paired_frames", r.paired_frames},
                      {"samples", r.samples},
                      {"by_depth", nlohmann::json::array()},
                      {"by_region", nlohmann::json::array()},
                      {"registration", ToJson(r.registration)},
                      {"walls", nlohmann::json::array()},
                      {"error_map", "error_map.png"}};
  for (const auto& c : r.by_depth) j["by_depth"].push_back(ToJson(c));
  for (const auto& c : r.by_region) j["by_region"].push_back(ToJson(c));
  for (const auto& w : r.walls)
    j["walls"].push_back({{"frame", w.frame},
                          {"depth_m", w.depth_m},
                          {"pixels", w.pixels},
                          {"rms_mm", 1e3 * w.rms_m},
                          {"largest_region_mean_mm", 1e3 * w.largest_region_mean_m},
                          {"largest_region", w.largest_region}});
  return j;
}

std::string CheckHtml(const nlohmann::json& j) {
  std::string html =
      "<!doctype html><html><head><meta charset=\"utf-8\"><title>speckle check</title><style>"
      "body{font-family:sans-serif;margin:2em}td,th{padding:2px 8px;text-align:right}"
      "td:first-child{text-align:left}</style></head><body>\n";
  html += fmt::format(
      "<h1>check: {}</h1>\n<p>calibration {}<br>recording {}<br>{} of {} board frames paired, {} "
      "samples</p>\n<ul>",
      Cell(j["verdict"]), Cell(j["calibration"]), Cell(j["recording"]), Cell(j["paired_frames"]),
      Cell(j["board_frames"]), Cell(j["samples"]));
  for (const auto& why : j["reasons"]) html += "<li>" + Cell(why) + "</li>";
  html += "</ul>\n<h2>By depth</h2>\n" + Table(j["by_depth"]) + "<h2>By image region</h2>\n" + Table(j["by_region"]);
  const auto& g = j["registration"];
  html += fmt::format(
      "<h2>Registration</h2>\n<p>outlines off by ({}, {}) px, grown {} px over {} poses: {} sigma, {}</p>\n",
      Cell(g["shift_px"][0]), Cell(g["shift_px"][1]), Cell(g["growth_px"]), Cell(g["poses"]), Cell(g["sigmas"]),
      Cell(g["verdict"]));
  html +=
      "<h2>Depth error over the image</h2>\n<p>blue: nearer than the board, red: farther (±5 mm full scale); "
      "black: no board there</p><img src=\"error_map.png\">\n";
  html +=
      "<h2>Walls (shown, not judged)</h2>\n<table><tr><th>frame</th><th>depth_m</th><th>rms_mm</th>"
      "<th>largest_region_mean_mm</th><th>where</th></tr>\n";
  for (const auto& w : j["walls"])
    html += fmt::format("<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n", Cell(w["frame"]),
                        Cell(w["depth_m"]), Cell(w["rms_mm"]), Cell(w["largest_region_mean_mm"]),
                        Cell(w["largest_region"]));
  return html + "</table>\n</body></html>\n";
}

void WriteCheckFolder(const std::string& given, const CheckArtifact& artifact) {
  const fs::path out = NormalizeOutPath(given, "--out");
  RemoveStaleStaging(fs::absolute(out).parent_path());
  if (fs::exists(out)) throw InputError(out.string() + ": exists; check overwrites nothing, choose a new --out");
  const nlohmann::json j = ToJson(artifact);
  WriteFolderAside(
      PartialPathFor(fs::absolute(out)),
      [&](const fs::path& staging) {
        WriteMap(artifact.result, staging / "error_map.png");
        std::ofstream(staging / "check.json") << j.dump(2) << "\n";
        std::ofstream(staging / "check.html") << CheckHtml(j);
      },
      [&](const fs::path& staging) { return RenameInto(staging, out); });
  spdlog::info("check.json, check.html and error_map.png in {}", out.string());
}

}  // namespace speckle
