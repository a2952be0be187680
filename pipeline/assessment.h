#pragma once
// The plain line a user reads first, on the terminal and at the top of
// report.html: "good", "limited by ...", or "not usable: ...", from what the
// run found (issue 47: the page carries what the terminal says).
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace speckle {

// report.json's "assessment" (status: good, limited, not usable, or not
// assessed without a noise floor; its line; limited_by; ratio_to_floor), "cameras"
// (calibration.json's, with their sigmas) and "warnings" (every warning the
// run logged, and the summary's), from the version's two documents as they
// are about to be written.
void AddAssessment(nlohmann::json& report, const nlohmann::json& calibration,
                   const std::vector<std::string>& logged_warnings);

// "result       good: ..." for the terminal summary, from report["assessment"].
std::string AssessmentLine(const nlohmann::json& report);

}  // namespace speckle
