#pragma once
// Error tiers (../shared/docs/style.md, point 5): bad input is an InputError whose message
// names the file, frame or field and says what was expected; the CLIs map it
// to kExitBadInput. Programming errors stay std::logic_error.
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace speckle {

// Exit codes shared by every command-line tool.
inline constexpr int kExitOk = 0;
inline constexpr int kExitInternal = 1;
inline constexpr int kExitUsage = 2;
inline constexpr int kExitBadInput = 3;
inline constexpr int kExitNoDevice = 4;

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A file or record written by a newer (or unknown) schema than we understand.
class SchemaVersionError : public InputError {
 public:
  using InputError::InputError;
};

// No sensor attached (live capture only).
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A filesystem_error's message without libstdc++'s "filesystem error: "
// opening, for messages that say what failed in their own words (it used to
// read "file system: filesystem error: ...").
inline std::string_view FileSystemMessage(const std::filesystem::filesystem_error& e) {
  constexpr std::string_view kLibraryPrefix = "filesystem error: ";
  std::string_view what = e.what();
  if (what.substr(0, kLibraryPrefix.size()) == kLibraryPrefix) what.remove_prefix(kLibraryPrefix.size());
  return what;
}

}  // namespace speckle
