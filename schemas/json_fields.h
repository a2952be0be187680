#pragma once
// Strict reading of one JSON object: every key read must have the expected
// type, required keys must be present, and keys nobody read are rejected, so
// a typo in a hand-written file is an error naming the key, not a silent
// default.
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "schemas/errors.h"

namespace speckle {

// Parses a JSON file; InputError names the file when it is missing or invalid.
nlohmann::json ReadJsonFile(const std::string& path);

class JsonFields {
 public:
  // `where` prefixes every message, e.g. "scenario.json: effects[2]".
  JsonFields(const nlohmann::json& object, std::string where);

  template <typename T>
  T Required(const std::string& key) {
    return Convert<T>(Find(key, /*required=*/true), key);
  }
  template <typename T>
  T Optional(const std::string& key, T fallback) {
    const nlohmann::json* value = Find(key, /*required=*/false);
    return value ? Convert<T>(value, key) : fallback;
  }
  // A number that must lie in [lo, hi].
  double RequiredInRange(const std::string& key, double lo, double hi);
  double OptionalInRange(const std::string& key, double fallback, double lo, double hi);
  bool Has(const std::string& key) const { return object_.contains(key); }
  const nlohmann::json& RequiredValue(const std::string& key) { return *Find(key, true); }
  const nlohmann::json* OptionalValue(const std::string& key) { return Find(key, false); }
  std::string Path(const std::string& key) const { return where_ + "." + key; }

  // Throws InputError naming the first key that was never read.
  void RejectUnknownKeys() const;

 private:
  const nlohmann::json* Find(const std::string& key, bool required);
  template <typename T>
  T Convert(const nlohmann::json* value, const std::string& key) const {
    try {
      return value->get<T>();
    } catch (const nlohmann::json::exception&) {
      throw InputError(where_ + "." + key + ": expected " + TypeName<T>() + ", found " +
                       value->dump());
    }
  }
  template <typename T>
  static std::string TypeName() {
    if constexpr (std::is_same_v<T, bool>) return "true or false";
    else if constexpr (std::is_integral_v<T>) return "an integer";
    else if constexpr (std::is_floating_point_v<T>) return "a number";
    else if constexpr (std::is_same_v<T, std::string>) return "a string";
    else return "a value of another type";
  }

  const nlohmann::json& object_;
  std::string where_;
  std::set<std::string> read_;
};

}  // namespace speckle
