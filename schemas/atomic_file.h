#pragma once
// Files that appear whole or not at all: write to a temporary name in the
// same directory, fsync, then rename over the final name.
#include <filesystem>
#include <string_view>

namespace speckle {

void WriteFileAtomically(const std::filesystem::path& path, std::string_view contents);

// fsync a file or directory so a rename into it survives a power cut.
void SyncPath(const std::filesystem::path& path);

// UTC now as ISO 8601, e.g. "2026-11-22T13:05:00Z".
std::string UtcNowIso8601();

}  // namespace speckle
