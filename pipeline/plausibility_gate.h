#pragma once
// Every writer's side of apply/plausibility.h: run-pipeline and refit check
// the calibration they are about to write, keep it for inspection, and do not
// let it pass as a result.
#include <filesystem>
#include <nlohmann/json.hpp>

namespace speckle {

// Stores calibration["plausibility"] before the version is written.
void MarkPlausibility(nlohmann::json& calibration, bool accept_implausible);

// After the version is written: one not plausible ends the run as bad input
// (exit 3), naming the version, what is wrong and the likely cause (it is no
// session's newest for apply-calibration or refit); one the user accepted is
// warned about.
void EndIfImplausible(const std::filesystem::path& version, const nlohmann::json& plausibility);

}  // namespace speckle
