#include "formats/python_literal.h"

#include <cctype>

#include "schemas/errors.h"

namespace speckle::formats {
namespace {

// A quoted string from text[i] (its opening quote) to JSON, i past its close.
std::string JsonString(const std::string& text, std::size_t& i, const std::string& origin) {
  const char quote = text[i++];
  std::string raw;
  for (; i < text.size() && text[i] != quote; ++i) {
    if (text[i] == '\\' && i + 1 < text.size()) raw += text[i++];
    raw += text[i];
  }
  if (i >= text.size()) throw InputError(origin + ": a string is not closed");
  ++i;
  // Python's \' needs no escape in JSON; a bare " does.
  std::string out = "\"";
  for (std::size_t k = 0; k < raw.size(); ++k) {
    if (raw[k] == '\\' && k + 1 < raw.size() && raw[k + 1] == '\'') continue;
    if (raw[k] == '"' && (k == 0 || raw[k - 1] != '\\')) out += '\\';
    out += raw[k];
  }
  return out + "\"";
}

// Drops a trailing comma before a closing bracket (Python allows it, JSON does not).
void Close(std::string& json, char bracket) {
  const auto last = json.find_last_not_of(" \n\t\r");
  if (last != std::string::npos && json[last] == ',') json.erase(last);
  json += bracket;
}

// An exponent's e follows a digit or a point.
bool InNumber(const std::string& json) {
  return !json.empty() && (std::isdigit(static_cast<unsigned char>(json.back())) || json.back() == '.');
}

}  // namespace

nlohmann::json PythonLiteralToJson(const std::string& text, const std::string& origin) {
  std::string json;
  for (std::size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (c == '#') {
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (c == '\'' || c == '"') {
      json += JsonString(text, i, origin);
    } else if ((c == 'b' || c == 'r') && i + 1 < text.size() && (text[i + 1] == '\'' || text[i + 1] == '"')) {
      ++i;  // bytes or raw: the characters alone
    } else if (c == '(') {
      json += '[';
      ++i;
    } else if (c == ')' || c == ']' || c == '}') {
      Close(json, c == ')' ? ']' : c);
      ++i;
    } else if (std::isalpha(static_cast<unsigned char>(c)) && !InNumber(json)) {
      std::size_t end = i;
      while (end < text.size() && std::isalnum(static_cast<unsigned char>(text[end]))) ++end;
      const std::string word = text.substr(i, end - i);
      if (word == "True")
        json += "true";
      else if (word == "False")
        json += "false";
      else if (word == "None")
        json += "null";
      else
        throw InputError(origin + ": \"" + word + "\" is not a Python literal (expected a camera model file)");
      i = end;
    } else {
      json += c;
      ++i;
    }
  }
  try {
    return nlohmann::json::parse(json);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(origin + ": not a Python literal this tool reads (" + e.what() + ")");
  }
}

}  // namespace speckle::formats
