#include "schemas/atomic_folder.h"

#include "schemas/atomic_file.h"
#include "schemas/staging.h"

namespace speckle {
namespace fs = std::filesystem;

fs::path WriteFolderAside(const fs::path& staging, const std::function<void(const fs::path&)>& write,
                          const std::function<fs::path(const fs::path&)>& publish) {
  CreateStagingFolder(staging);
  try {
    write(staging);
    RemoveStagingMarker(staging);
    SyncPath(staging);
    return publish(staging);
  } catch (...) {
    std::error_code ignored;
    fs::remove_all(staging, ignored);
    throw;
  }
}

fs::path RenameInto(const fs::path& staging, const fs::path& target) {
  fs::rename(staging, target);
  SyncPath(fs::absolute(target).parent_path());
  return target;
}

}  // namespace speckle
