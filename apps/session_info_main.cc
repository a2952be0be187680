// session-info SESSION_DIR: what a session holds, validated against the format.
#include <spdlog/spdlog.h>
#include <iostream>
#include "apps/cli_main.h"

#include "recorder/session_inspection.h"
#include "schemas/errors.h"

int main(int argc, char** argv) {
  using namespace speckle;
  CLI::App app{"Print what a session holds and validate it. Exit 0 when valid, 3 when not."};
  std::string session;
  bool json = false;
  app.add_option("SESSION_DIR", session, "session directory")->required();
  app.add_flag("--json", json, "print the summary as JSON");
  return RunCli("session-info", app, argc, argv, [&] {
    const SessionSummary summary = InspectSession(session);
    std::cout << (json ? ToJson(summary).dump(2) + "\n" : FormatSummary(summary));
    return summary.problems.empty() ? kExitOk : kExitBadInput;
  });
}
