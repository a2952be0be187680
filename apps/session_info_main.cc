// session-info SESSION_DIR: what a session holds, validated against the format.
#include <CLI/CLI.hpp>
#include <iostream>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "recorder/session_inspection.h"
#include "schemas/errors.h"

int main(int argc, char** argv) {
  using namespace speckle;
  spdlog::set_default_logger(spdlog::stderr_color_mt("session-info"));
  spdlog::set_pattern("%^%l%$: %v");
  CLI::App app{"Print what a session holds and validate it. Exit 0 when valid, 3 when not."};
  std::string session;
  bool json = false;
  app.add_option("SESSION_DIR", session, "session directory")->required();
  app.add_flag("--json", json, "print the summary as JSON");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  }
  try {
    const SessionSummary summary = InspectSession(session);
    std::cout << (json ? ToJson(summary).dump(2) + "\n" : FormatSummary(summary));
    return summary.problems.empty() ? kExitOk : kExitBadInput;
  } catch (const InputError& e) {
    spdlog::error("{}", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    spdlog::error("internal error: {}", e.what());
    return kExitInternal;
  }
}
