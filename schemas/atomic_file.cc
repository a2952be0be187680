#include "schemas/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <fstream>
#include <random>
#include <string>

#include "schemas/errors.h"

namespace speckle {

void SyncPath(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return;  // best effort: the data is written, only durability is weaker
  ::fsync(fd);
  ::close(fd);
}

void WriteFileAtomically(const std::filesystem::path& path, std::string_view contents) {
  std::random_device entropy;
  const auto temp = path.parent_path() / ("." + path.filename().string() + ".tmp-" + std::to_string(entropy()));
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.flush();
    if (!out) {
      const int error = errno;
      std::error_code ignored;
      std::filesystem::remove(temp, ignored);
      throw WriteFailure(temp, error);
    }
  }
  SyncPath(temp);
  std::filesystem::rename(temp, path);
  SyncPath(path.parent_path().empty() ? "." : path.parent_path());
}

std::string UtcNowIso8601() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

}  // namespace speckle
