#pragma once
// The diagnosis's verdict in words for one session: its commands (the stage
// leaves them as parts, lab/diagnosis/model_diagnosis.h) written out as the user
// would type them.
#include <string>

#include <nlohmann/json.hpp>

#include "lab/diagnosis/model_diagnosis.h"

namespace speckle {

// One paragraph, e.g. "...; adding albedo_bias cuts ... — run: refit S --add-effect albedo_bias".
// refit: how the user calls the refit tool (e.g. "build/refit", beside the
// tool that ran: apps/cli_main.h's ToolBeside).
std::string VerdictText(const Diagnosis& d, const std::string& session, const std::string& refit = "refit");

// A word the shell passes as it is, or the word in single quotes, so that a
// printed command runs when pasted.
std::string ShellWord(const std::string& word);

// report.json's "next_steps": each command of the verdict as
// {"kind": "add_effect" | "base_form" | "formula_model", "argument", "command"}.
nlohmann::json NextStepsJson(const Diagnosis& d, const std::string& session, const std::string& refit = "refit");

}  // namespace speckle
