#pragma once
// What every fuzz target shares: a private scratch folder (tmpfs when there
// is one) to write the fuzzer's bytes to, since the readers take paths, and
// the rule that bad input may only end as InputError or H5::Exception -- the
// two the command-line tools map to "bad input" (exit 3). Anything else that
// escapes (another exception, a crash, a sanitizer report, a hang) is a
// finding.
#include <H5Cpp.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "schemas/errors.h"

namespace speckle::fuzz {

inline const std::filesystem::path& Scratch() {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path base =
        std::filesystem::exists("/dev/shm") ? "/dev/shm" : std::filesystem::temp_directory_path();
    const auto d = base / ("speckle-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    H5::Exception::dontPrint();  // the fuzzer's own output stays readable
    return d;
  }();
  return dir;
}

inline void WriteBytes(const std::filesystem::path& path, const std::uint8_t* data, std::size_t size) {
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

inline void WriteBytes(const std::filesystem::path& path, const std::string& bytes) {
  WriteBytes(path, reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
}

// Runs `read`; the refusals the tools report as bad input are expected.
template <class Read>
void ExpectOnlyInputErrors(Read&& read) {
  try {
    read();
  } catch (const InputError&) {
  } catch (const H5::Exception&) {
  }
}

}  // namespace speckle::fuzz
