#pragma once
// What every command-line tool's main does: logs to stderr, parses the
// command line, runs the tool, and maps errors to exit codes in order
// (usage 2, bad input 3, no device 4, anything else 1).
#include <CLI/CLI.hpp>
#include <functional>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "schemas/errors.h"

namespace speckle {

inline int RunCli(const char* name, CLI::App& app, int argc, char** argv, const std::function<int()>& run) {
  spdlog::set_default_logger(spdlog::stderr_color_mt(name));
  spdlog::set_pattern("%^%l%$: %v");
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
  } catch (const std::exception& e) {
    spdlog::error("internal error: {}", e.what());
    return kExitInternal;
  }
}

}  // namespace speckle
