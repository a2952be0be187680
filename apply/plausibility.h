#pragma once
// What no Kinect v1 / PrimeSense-class sensor gives, stock or behind an
// add-on wide-angle lens: the one check that every writer (run-pipeline,
// refit) runs before a version is written and every reader
// (apply-calibration, measure, refit's parent) runs after reading one. A
// result outside it almost always comes from a wrong board description
// (--squares counts squares, --square-size is in metres), which a fit
// otherwise turns into a confident, wrong calibration.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace speckle::apply {

// Each way calibration.json's cameras and base form depart from the sensor
// family, with its likely cause; empty when none does. Reads leniently: a
// missing number is not checked (the readers refuse it themselves).
std::vector<std::string> ImplausibleCalibration(const nlohmann::json& calibration);

// calibration.json's "plausibility": the problems found when it was written,
// and whether the user accepted them (run-pipeline / refit --accept-implausible).
nlohmann::json PlausibilityJson(const std::vector<std::string>& problems, bool accepted);

// The problems a reader must refuse: found now and not accepted when written.
// Empty when the calibration is plausible or its problems were accepted.
std::vector<std::string> UnacceptedProblems(const nlohmann::json& calibration);

// How every writer and reader says it, before what it does about it.
inline constexpr const char* kNotOfTheFamily = "not a calibration a Kinect v1 / PrimeSense sensor gives";

// One line for a message: "(1) ...; (2) ...".
std::string JoinProblems(const std::vector<std::string>& problems);

}  // namespace speckle::apply
