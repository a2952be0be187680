#include "pipeline/plausibility_gate.h"

#include <spdlog/spdlog.h>

#include "apply/plausibility.h"
#include "schemas/errors.h"

namespace speckle {

void MarkPlausibility(nlohmann::json& calibration, bool accept_implausible) {
  calibration["plausibility"] = apply::PlausibilityJson(apply::ImplausibleCalibration(calibration), accept_implausible);
}

void EndIfImplausible(const std::filesystem::path& version, const nlohmann::json& stored) {
  const auto problems = stored.at("problems").get<std::vector<std::string>>();
  if (problems.empty()) return;
  if (stored.value("accepted", false)) {
    spdlog::warn("{}: kept with --accept-implausible, though no sensor of the family gives it: {}", version.string(),
                 apply::JoinProblems(problems));
    return;
  }
  throw InputError(version.string() + " is " + apply::kNotOfTheFamily +
                   ", so it is kept for inspection but "
                   "is no session's newest (apply-calibration and refit pass it by): " +
                   apply::JoinProblems(problems) +
                   ". Correct session.json's rig and run run-pipeline again; for a sensor outside the family, "
                   "--accept-implausible keeps the result as a calibration");
}

}  // namespace speckle
