#pragma once
// A calibration version read back for a refit: its calibration.json and
// report.json brought up to the current schemas. Older versions lack fields,
// which then read null ("not measured"); a version newer than this tool is
// refused, naming the file.
#include <filesystem>
#include <nlohmann/json.hpp>

namespace speckle {

struct ParentVersion {
  nlohmann::json calibration, report;
};
ParentVersion ReadParentVersion(const std::filesystem::path& version_dir);  // throws InputError

}  // namespace speckle
