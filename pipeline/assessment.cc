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
  const nlohmann::json& frames = report.contains("frames") ? report["frames"] : nlohmann::json::array();
  for (const auto& f : frames.is_array() ? frames : nlohmann::json::array()) {
    if (!f.is_object() || f.value("recording", nlohmann::json()) != "planar") continue;
    ++planar;
    rejected += f.contains("reason") && !f["reason"].is_null();
  }
  if (planar == 0 || 2 * rejected <= planar) return "";
  return fmt::format(
      "{} of {} wall snapshots were rejected (each one's reason is under its mask): record the walls again, the "
      "sensor square to a flat wall that fills the view, from near to far",
      rejected, planar);
}

std::string CameraWarning(const nlohmann::json& calibration) {
  const auto warning = calibration.at("cameras").value("depth_intrinsics_warning", nlohmann::json());
  return warning.is_string() ? warning.get<std::string>() : "";
}

// The diagnosis's own judgement of the model: complete is within its
// complete_ratio of the floor (the hunt's 1.15).
std::vector<std::string> LimitedBy(const nlohmann::json& report, const nlohmann::json& calibration,
                                   const std::string& walls) {
  const nlohmann::json& d = report.at("diagnosis");
  std::vector<std::string> out;
  const double ratio = d.value("ratio_to_floor", 0.0);
  const std::string conclusion = d.value("conclusion", "");
  if (!d.value("complete", false)) {
    const auto recommended = d.value("recommended", nlohmann::json());
    out.push_back(fmt::format("the model: held out {:.2f}x the noise floor{}", ratio,
                              recommended.is_string() ? "; the verdict adds " + recommended.get<std::string>() : ""));
  }
  if (conclusion == "record_more_poses") out.push_back("the poses: too few reach where the model needs them");
  if (conclusion == "recalibrate_cameras") out.push_back("the cameras' calibration uncertainty");
  if (!CameraWarning(calibration).empty())
    out.push_back("the depth camera's intrinsics, loosely pinned by this session");
  if (!walls.empty()) out.push_back("the wall snapshots: most were rejected");
  const nlohmann::json unseen = report.value("unseen_regions", nlohmann::json::object());
  if (unseen.is_object() && unseen.value("beyond_sigma", false))
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
  const std::string walls = FewWalls(report);
  const std::vector<std::string> limits = LimitedBy(report, calibration, walls);
  const double ratio = report.at("diagnosis").value("ratio_to_floor", 0.0);
  nlohmann::json a = {{"ratio_to_floor", ratio}, {"limited_by", limits}};
  if (!problems.empty()) {
    a["status"] = "not usable";
    a["line"] = fmt::format("not usable: {}: {}", apply::kNotOfTheFamily, apply::JoinProblems(problems));
  } else if (!(ratio > 0)) {  // no noise floor measured: nothing to judge the model by
    a["status"] = "not assessed";
    a["line"] = "not assessed: no noise floor was measured to judge the model by";
  } else if (!limits.empty()) {
    a["status"] = "limited";
    a["line"] = fmt::format("limited by {}", fmt::join(limits, "; and by "));
  } else {
    a["status"] = "good";
    a["line"] = fmt::format("good: held out {:.2f}x the noise floor, no camera warning", ratio);
  }
  std::vector<std::string> warnings = logged_warnings;
  const std::string camera = CameraWarning(calibration);
  if (!camera.empty() && std::find(warnings.begin(), warnings.end(), camera) == warnings.end())
    warnings.push_back(camera);
  if (!walls.empty()) warnings.push_back(walls);
  report["assessment"] = a;
  report["cameras"] = calibration.at("cameras");
  report["warnings"] = warnings;
}

std::string AssessmentLine(const nlohmann::json& report) {
  if (!report.contains("assessment")) return "";
  return fmt::format("result       {}\n", report["assessment"].value("line", ""));
}

}  // namespace speckle
