#pragma once
// What every command-line tool's main does: logs to stderr, parses the
// command line, runs the tool, and maps errors to exit codes in order
// (usage 2, bad input 3, no device 4, anything else 1).
//
// Two kinds of failure are not std::exceptions and would otherwise end the
// tool with SIGABRT: a CHECK inside Ceres or glog (the failure function below
// turns it into exit 1 after glog's own line says which check), and
// H5::Exception, thrown by the HDF5 C++ API on a dataset it cannot read
// (mapped to bad input: the file is damaged or not what it claims). A file
// HDF5 could not close (a full disk) ends the tool without HDF5's shutdown,
// which would crash on it.
#include <H5Cpp.h>
#include <glog/logging.h>
#include <malloc.h>
#include <unistd.h>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <new>
#include <string>

#include "schemas/errors.h"
#include "schemas/h5_access.h"

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

// glibc hands large blocks back to the kernel as soon as they are freed and
// maps them afresh on the next allocation; the pipeline allocates and frees a
// frame's worth (hundreds of kB) per frame and per fit on each TBB thread, and
// on a virtual machine the page faults cost more than the work: run-pipeline
// on a 20-pose hunt session spent 6.5 of its 13 s of CPU in the kernel
// (10.9-11.7 s wall -> 4.9 s with this, 0.6 s in the kernel, idle machine,
// 2026-11-28; peak memory 222 -> 296 MB).
// Blocks up to 32 MB stay on the heap, and the heap keeps 64 MB of slack.
inline void KeepFreedMemoryForReuse() {
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  mallopt(M_TOP_PAD, 64 << 20);
}

// A path the command line names that is not there is bad input (exit 3,
// naming it), as is every file a reader cannot open; CLI11's Existing*
// checks would end such a typo as a usage error (2). Empty: not given.
inline void RequireExisting(const std::string& path, const std::string& what, bool directory) {
  namespace fs = std::filesystem;
  if (path.empty() || (directory ? fs::is_directory(path) : fs::is_regular_file(path))) return;
  const char* kind = directory ? "directory" : "file";
  throw InputError(what + " " + path + (fs::exists(path) ? std::string(": not a ") : std::string(": no such ")) + kind);
}

// How the user calls another of our tools: beside this one when it was
// called by a path (build/run-pipeline -> build/refit), by its name when it
// was found on PATH. The verdict's commands then run when pasted.
inline std::string ToolBeside(const char* argv0, const std::string& tool) {
  const std::string self = argv0 ? argv0 : "";
  const std::size_t slash = self.rfind('/');
  return slash == std::string::npos ? tool : self.substr(0, slash + 1) + tool;
}

inline int RunMapped(CLI::App& app, int argc, char** argv, const std::function<int()>& run) {
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
  } catch (const UsageError& e) {
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
    spdlog::error("file system: {}", FileSystemMessage(e));
    return kExitBadInput;
  } catch (const std::bad_alloc&) {
    spdlog::error("internal error: out of memory");
    return kExitInternal;
  } catch (const std::exception& e) {
    spdlog::error("internal error: {}", e.what());
    return kExitInternal;
  }
}

inline int RunCli(const char* name, CLI::App& app, int argc, char** argv, const std::function<int()>& run) {
  KeepFreedMemoryForReuse();
  spdlog::set_default_logger(spdlog::stderr_color_mt(name));
  spdlog::set_pattern("%^%l%$: %v");
  google::InstallFailureFunction(&ExitOnLibraryCheckFailure);
  const int code = RunMapped(app, argc, argv, run);
  if (h5::AnyFileAbandoned()) {
    // HDF5's shutdown at exit would close the abandoned file again and read
    // freed memory (schemas/h5_access.h): end here, output flushed.
    spdlog::default_logger()->flush();
    std::fflush(nullptr);
    ::_exit(code);
  }
  return code;
}

}  // namespace speckle
