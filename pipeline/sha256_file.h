#pragma once
// A file's SHA-256, as calibration.json records each session input's.
#include <filesystem>
#include <string>

namespace speckle {

// Hex digest; throws InputError when the file cannot be opened.
std::string Sha256File(const std::filesystem::path& path);
// Hex digest of bytes in memory (a run's fingerprint).
std::string Sha256Text(const std::string& text);

}  // namespace speckle
