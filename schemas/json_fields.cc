#include "schemas/json_fields.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

namespace speckle {

nlohmann::json ParseJsonText(const std::string& text, const std::string& where) {
  // The keys of each object being parsed, innermost last.
  std::vector<std::set<std::string>> keys;
  const auto check = [&](int depth, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    if (depth > kMaxJsonDepth)
      throw InputError(where + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    if (event == Event::object_start) keys.emplace_back();
    if (event == Event::object_end && !keys.empty()) keys.pop_back();
    if (event == Event::key && !keys.empty() && !keys.back().insert(parsed.get<std::string>()).second)
      throw InputError(where + ": key \"" + parsed.get<std::string>() + "\" appears twice in one object");
    return true;
  };
  try {
    return nlohmann::json::parse(text, check);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(where + ": not valid JSON: " + e.what());
  }
}

nlohmann::json ReadJsonFile(const std::string& path) {
  // Only a regular file of bounded size: a FIFO blocked every reader for
  // ever, and a link to /dev/zero was read without end.
  constexpr std::uintmax_t kMaxJsonFileBytes = 256ull << 20;  // a pattern version's calibration.json is 13 MB
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (std::filesystem::is_directory(status)) throw InputError(path + ": is a folder, expected a JSON file");
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    throw InputError(path + ": is not a regular file (a pipe, device or socket); expected a JSON file");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxJsonFileBytes)
    throw InputError(path + ": " + std::to_string(size) + " bytes, more than any JSON file the tools write (" +
                     std::to_string(kMaxJsonFileBytes) + ")");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw InputError(path + ": cannot read");
  return ParseJsonText(text.str(), path);
}

std::string JsonExcerpt(const nlohmann::json& value) {
  if (value.is_object()) return "an object of " + std::to_string(value.size()) + " keys";
  if (value.is_array()) return "an array of " + std::to_string(value.size()) + " values";
  std::string text = value.dump();
  if (text.size() > 80) text = text.substr(0, 77) + "...";
  return text;
}

JsonFields::JsonFields(const nlohmann::json& object, std::string where) : object_(object), where_(std::move(where)) {
  if (!object_.is_object()) throw InputError(where_ + ": expected a JSON object, found " + JsonExcerpt(object_));
}

const nlohmann::json* JsonFields::Find(const std::string& key, bool required) {
  read_.insert(key);
  auto it = object_.find(key);
  if (it == object_.end() || it->is_null()) {
    if (required) throw InputError(where_ + ": missing required key \"" + key + "\"");
    return nullptr;
  }
  return &*it;
}

double JsonFields::RequiredInRange(const std::string& key, double lo, double hi) {
  const double value = Required<double>(key);
  if (!std::isfinite(value) || value < lo || value > hi) {
    throw InputError(Path(key) + ": expected a number in [" + nlohmann::json(lo).dump() + ", " +
                     nlohmann::json(hi).dump() + "], found " + nlohmann::json(value).dump());
  }
  return value;
}

double JsonFields::OptionalInRange(const std::string& key, double fallback, double lo, double hi) {
  read_.insert(key);  // a key the reader knows, given or not (RejectUnknownKeys lists them)
  return Has(key) ? RequiredInRange(key, lo, hi) : fallback;
}

void JsonFields::RejectUnknownKeys() const {
  for (const auto& [key, value] : object_.items()) {
    if (!read_.count(key)) {
      std::string known;
      for (const auto& k : read_) known += (known.empty() ? "" : ", ") + k;
      throw InputError(where_ + ": unknown key \"" + key + "\" (known keys: " + known + ")");
    }
  }
}

}  // namespace speckle
