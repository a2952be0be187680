#pragma once
// check's artifact: a folder (written aside, then renamed; nothing
// overwritten) with check.json (schema speckle.check), check.html (the same
// tables, readable offline) and error_map.png (the mean depth error per
// block of the depth image).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "apps/calibration_check.h"

namespace speckle {

struct CheckArtifact {
  std::filesystem::path calibration_file;
  std::string recording;
  const CheckResult& result;
};

nlohmann::json ToJson(const CheckArtifact& artifact);
std::string CheckHtml(const nlohmann::json& check);

// Throws InputError when `out` exists.
void WriteCheckFolder(const std::string& out, const CheckArtifact& artifact);

}  // namespace speckle
