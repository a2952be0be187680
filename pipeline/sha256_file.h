#pragma once
// A file's SHA-256, as calibration.json records each session input's.
#include <filesystem>
#include <string>

namespace speckle {

// Hex digest; throws InputError when the file cannot be opened.
std::string Sha256File(const std::filesystem::path& path);

}  // namespace speckle
