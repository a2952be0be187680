#pragma once
// Writing a folder so that readers see all of it or nothing: filled aside (a
// staging folder, see schemas/staging.h), synced, then renamed into place. A
// failure anywhere removes the staging folder; a killed process leaves it for
// the next run's RemoveStaleStaging.
#include <filesystem>
#include <functional>

namespace speckle {

// Creates `staging`, lets `write` fill it, syncs it, and lets `publish` move it
// into place (returning where); removes `staging` if any of them throws.
std::filesystem::path WriteFolderAside(
    const std::filesystem::path& staging, const std::function<void(const std::filesystem::path&)>& write,
    const std::function<std::filesystem::path(const std::filesystem::path&)>& publish);

// The usual `publish`: rename to `target` and sync the folder holding it.
std::filesystem::path RenameInto(const std::filesystem::path& staging, const std::filesystem::path& target);

}  // namespace speckle
