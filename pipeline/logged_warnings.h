#pragma once
// Every warning a tool logged while it ran, kept for report.json: report.html
// carries what the terminal said (issue 47), not only what the summary holds.
#include <string>
#include <vector>

namespace speckle {

// Adds the keeping sink to the default logger; call once, before the run.
void KeepLoggedWarnings();

// The warnings (and errors) logged since, in order, each once.
std::vector<std::string> LoggedWarnings();

}  // namespace speckle
