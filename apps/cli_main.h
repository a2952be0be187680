#pragma once
// What every command-line tool's main does: logs to stderr, parses the
// command line, runs the tool, and maps errors to exit codes in order
// (usage 2, bad input 3, no device 4, anything else 1).
//
// Two kinds of failure are not std::exceptions and would otherwise end the
// tool with SIGABRT: a CHECK inside Ceres or glog (the failure function below
// turns it into exit 1 after glog's own line says which check), and
// H5::Exception, thrown by the HDF5 C++ API on a dataset it cannot read
// (mapped to bad input: the file is damaged or not what it claims).
#include <H5Cpp.h>
#include <glog/logging.h>
#include <unistd.h>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <new>

#include "schemas/errors.h"

namespace speckle {

// glog's failure function may not return and may not throw (the fatal log
// message's destructor is noexcept): say what happened, then exit 1.
__attribute__((noreturn)) inline void ExitOnLibraryCheckFailure() {  // glog takes a noreturn function type
  static const char kMessage[] =
      "error: internal error: a check inside a library (Ceres/glog, the line above) failed; nothing was written "
      "to the output. Please report it with the input that caused it.\n";
  [[maybe_unused]] const ssize_t written = ::write(2, kMessage, sizeof kMessage - 1);
  ::_exit(kExitInternal);
}

inline int RunCli(const char* name, CLI::App& app, int argc, char** argv, const std::function<int()>& run) {
  spdlog::set_default_logger(spdlog::stderr_color_mt(name));
  spdlog::set_pattern("%^%l%$: %v");
  google::InstallFailureFunction(&ExitOnLibraryCheckFailure);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  try {
    return run();
  } catch (const CLI::ValidationError& e) {
    spdlog::error("{}", e.what());
    return kExitUsage;
  } catch (const InputError& e) {
    spdlog::error("{}", e.what());
    return kExitBadInput;
  } catch (const DeviceError& e) {
    spdlog::error("{}", e.what());
    return kExitNoDevice;
  } catch (const H5::Exception& e) {
    spdlog::error("HDF5 could not read a dataset ({}: {}): the file is damaged or not a Speckle file", e.getFuncName(),
                  e.getDetailMsg());
    return kExitBadInput;
  } catch (const std::filesystem::filesystem_error& e) {
    // A read-only session, a folder where a file belongs, a full disk: the
    // message names the path.
    spdlog::error("file system: {}", e.what());
    return kExitBadInput;
  } catch (const std::bad_alloc&) {
    spdlog::error("internal error: out of memory");
    return kExitInternal;
  } catch (const std::exception& e) {
    spdlog::error("internal error: {}", e.what());
    return kExitInternal;
  }
}

}  // namespace speckle
