#include "schemas/json_fields.h"

#include <cmath>
#include <fstream>

namespace speckle {

nlohmann::json ReadJsonFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(path + ": not valid JSON: " + e.what());
  }
}

JsonFields::JsonFields(const nlohmann::json& object, std::string where)
    : object_(object), where_(std::move(where)) {
  if (!object_.is_object()) throw InputError(where_ + ": expected a JSON object, found " + object_.dump());
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
