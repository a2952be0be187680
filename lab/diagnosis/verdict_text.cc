#include "lab/diagnosis/verdict_text.h"

#include <fmt/format.h>

#include <sstream>

namespace speckle {
namespace {

std::string Command(const VerdictPart& part, const std::string& unquoted_session, const std::string& unquoted_refit) {
  const std::string session = ShellWord(unquoted_session), refit = ShellWord(unquoted_refit);
  switch (part.kind) {
    case VerdictPart::Kind::kWords:
      return part.argument;
    case VerdictPart::Kind::kAddEffect: {
      std::string line = refit + " " + session;
      std::istringstream effects(part.argument);
      for (std::string effect; effects >> effect;) line += " --add-effect " + effect;
      return line;
    }
    case VerdictPart::Kind::kBaseForm:
      return fmt::format("{} {} --base-form {}", refit, session, part.argument);
    case VerdictPart::Kind::kFormulaModel:
      return fmt::format("{} {} --model MODEL.json", refit, session);
  }
  return part.argument;
}

const char* KindName(VerdictPart::Kind kind) {
  switch (kind) {
    case VerdictPart::Kind::kWords:
      return "words";
    case VerdictPart::Kind::kAddEffect:
      return "add_effect";
    case VerdictPart::Kind::kBaseForm:
      return "base_form";
    case VerdictPart::Kind::kFormulaModel:
      return "formula_model";
  }
  return "unknown";
}

}  // namespace

// A word the shell passes as it is, or the word in single quotes: a session
// path with a space made a command that failed with exit 2 when pasted.
std::string ShellWord(const std::string& word) {
  const bool plain = !word.empty() && word.find_first_not_of(
                                          "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                          "0123456789@%+=:,./_-") == std::string::npos;
  if (plain) return word;
  std::string quoted = "'";
  for (char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string VerdictText(const Diagnosis& d, const std::string& session, const std::string& refit) {
  std::string text;
  for (const VerdictPart& part : d.verdict) text += Command(part, session, refit);
  return text;
}

nlohmann::json NextStepsJson(const Diagnosis& d, const std::string& session, const std::string& refit) {
  nlohmann::json steps = nlohmann::json::array();
  for (const VerdictPart& part : d.verdict) {
    if (part.kind == VerdictPart::Kind::kWords) continue;
    steps.push_back(
        {{"kind", KindName(part.kind)}, {"argument", part.argument}, {"command", Command(part, session, refit)}});
  }
  return steps;
}

}  // namespace speckle
