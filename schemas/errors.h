#pragma once
// Error tiers (../shared/docs/style.md, point 5): bad input is an InputError whose message
// names the file, frame or field and says what was expected; the CLIs map it
// to kExitBadInput. Programming errors stay std::logic_error.
#include <cerrno>
#include <cstring>
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

// A command-line option's value that is malformed, outside its range or
// missing its companion option: usage (kExitUsage), like what CLI11 itself
// refuses, not bad input. The message names the option.
class UsageError : public std::runtime_error {
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

// A file that could not be written is bad input like a read-only or full
// disk met through std::filesystem (exit 3), named with errno's reason.
// `error`: errno right after the failed write (0 when the writer set none).
inline InputError WriteFailure(const std::filesystem::path& file, int error) {
  std::string why = error != 0 ? std::strerror(error) : "the write failed (a full disk?)";
  if (error == ENOSPC) why += ": the disk is full";
  return InputError(file.string() + ": could not write: " + why);
}

}  // namespace speckle
