#pragma once
// Strict reading of one JSON object: every key read must have the expected
// type, required keys must be present, and keys nobody read are rejected, so
// a typo in a hand-written file is an error naming the key, not a silent
// default.
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "schemas/errors.h"

namespace speckle {

// JSON nested deeper than this is refused while parsing: no file of ours
// nests beyond a handful of levels, and copying or printing a value 200k
// levels deep would overflow the stack.
inline constexpr int kMaxJsonDepth = 64;

// Parses JSON text; InputError names `where` when the text is invalid, nests
// deeper than kMaxJsonDepth or repeats a key within one object (the later
// value would silently win).
nlohmann::json ParseJsonText(const std::string& text, const std::string& where);
// Parses a JSON file (as ParseJsonText); InputError names the file when it is
// missing or invalid.
nlohmann::json ReadJsonFile(const std::string& path);
// A short, bounded description of a value for error messages: scalars as
// written (cut at 80 characters), objects and arrays by kind and size, never
// recursing into them.
std::string JsonExcerpt(const nlohmann::json& value);

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
    // nlohmann converts 2.9 to the integer 2 without a word.
    if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
      if (!value->is_number_integer())
        throw InputError(where_ + "." + key + ": expected " + TypeName<T>() + ", found " + JsonExcerpt(*value));
    }
    if constexpr (std::is_same_v<T, std::vector<double>> || std::is_same_v<T, std::vector<int>>) {
      // Name the element: "found an array of 3 values" does not say which.
      if (value->is_array())
        for (std::size_t i = 0; i < value->size(); ++i)
          if (!(*value)[i].is_number() || (std::is_same_v<T, std::vector<int>> && !(*value)[i].is_number_integer()))
            throw InputError(where_ + "." + key + "[" + std::to_string(i) + "]: expected " +
                             TypeName<typename T::value_type>() + ", found " + JsonExcerpt((*value)[i]));
    }
    try {
      return value->get<T>();
    } catch (const nlohmann::json::exception&) {
      throw InputError(where_ + "." + key + ": expected " + TypeName<T>() + ", found " + JsonExcerpt(*value));
    }
  }
  template <typename T>
  static std::string TypeName() {
    if constexpr (std::is_same_v<T, bool>)
      return "true or false";
    else if constexpr (std::is_integral_v<T>)
      return "an integer";
    else if constexpr (std::is_floating_point_v<T>)
      return "a number";
    else if constexpr (std::is_same_v<T, std::string>)
      return "a string";
    else if constexpr (std::is_same_v<T, std::vector<double>>)
      return "a list of numbers";
    else if constexpr (std::is_same_v<T, std::vector<int>>)
      return "a list of integers";
    else
      return "a value of another type";
  }

  const nlohmann::json& object_;
  std::string where_;
  std::set<std::string> read_;
};

}  // namespace speckle
