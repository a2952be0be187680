#include "pipeline/assessment.h"

#include <fmt/format.h>

#include <algorithm>

#include "apply/plausibility.h"

namespace speckle {
namespace {

// Most wall snapshots rejected (run-pipeline's summary warns of it too):
// the warning, or nothing.
std::string FewWalls(const nlohmann::json& report) {
  int planar = 0, rejected = 0;
  for (const auto& f : report.value("frames", nlohmann::json::array())) {
    if (f.value("recording", "") != "planar") continue;
    ++planar;
    rejected += f.contains("reason") && !f["reason"].is_null();
  }
  if (planar == 0 || 2 * rejected <= planar) return "";
  return fmt::format(
      "{} of {} wall snapshots were rejected (each one's reason is under its mask): record the walls again, the "
      "sensor square to a flat wall that fills the view, from near to far",
      rejected, planar);
}

std::vector<std::string> LimitedBy(const nlohmann::json& report, const nlohmann::json& calibration) {
  const nlohmann::json& d = report.at("diagnosis");
  std::vector<std::string> out;
  const double ratio = d.value("ratio_to_floor", 0.0);
  const std::string conclusion = d.value("conclusion", "");
  if (ratio > kGoodRatioToFloor) {
    const auto recommended = d.value("recommended", nlohmann::json());
    out.push_back(fmt::format("the model: held out {:.2f}x the noise floor{}", ratio,
                              recommended.is_string() ? "; the verdict adds " + recommended.get<std::string>() : ""));
  }
  if (conclusion == "record_more_poses") out.push_back("the poses: too few reach where the model needs them");
  if (conclusion == "recalibrate_cameras") out.push_back("the cameras' calibration uncertainty");
  const auto warning = calibration.at("cameras").value("depth_intrinsics_warning", nlohmann::json());
  if (warning.is_string()) out.push_back("the depth camera's intrinsics, loosely pinned by this session");
  if (!FewWalls(report).empty()) out.push_back("the wall snapshots: most were rejected");
  const nlohmann::json unseen = report.value("unseen_regions", nlohmann::json::object());
  if (unseen.value("beyond_sigma", false))
    out.push_back("extrapolation where no board pose reached (" + unseen.value("region", std::string("?")) + ")");
  if (calibration.value("plausibility", nlohmann::json::object()).value("accepted", false) &&
      !calibration["plausibility"].value("problems", nlohmann::json::array()).empty())
    out.push_back("a rig outside the Kinect family, kept with --accept-implausible");
  return out;
}

}  // namespace

void AddAssessment(nlohmann::json& report, const nlohmann::json& calibration,
                   const std::vector<std::string>& logged_warnings) {
  const std::vector<std::string> problems = apply::UnacceptedProblems(calibration);
  const std::vector<std::string> limits = LimitedBy(report, calibration);
  nlohmann::json a = {{"ratio_to_floor", report.at("diagnosis").value("ratio_to_floor", 0.0)},
                      {"good_ratio_to_floor", kGoodRatioToFloor},
                      {"limited_by", limits}};
  if (!problems.empty()) {
    a["status"] = "not usable";
    a["line"] = fmt::format("not usable: {}: {}", apply::kNotOfTheFamily, apply::JoinProblems(problems));
  } else if (!limits.empty()) {
    a["status"] = "limited";
    a["line"] = fmt::format("limited by {}", fmt::join(limits, "; and by "));
  } else {
    a["status"] = "good";
    a["line"] =
        fmt::format("good: held out {:.2f}x the noise floor, no camera warning", a["ratio_to_floor"].get<double>());
  }
  std::vector<std::string> warnings = logged_warnings;
  const auto camera_warning = calibration.at("cameras").value("depth_intrinsics_warning", nlohmann::json());
  if (camera_warning.is_string() &&
      std::find(warnings.begin(), warnings.end(), camera_warning.get<std::string>()) == warnings.end())
    warnings.push_back(camera_warning.get<std::string>());
  if (const std::string walls = FewWalls(report); !walls.empty()) warnings.push_back(walls);
  report["assessment"] = a;
  report["cameras"] = calibration.at("cameras");
  report["warnings"] = warnings;
}

std::string AssessmentLine(const nlohmann::json& report) {
  if (!report.contains("assessment")) return "";
  return fmt::format("result       {}\n", report["assessment"].value("line", ""));
}

}  // namespace speckle
