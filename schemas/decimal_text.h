#pragma once
// Decimal numbers from file names and text formats (INDEX.txt times, frame
// numbers, calibration version folders) without std::stoll, which throws a
// bare "stoll" on 20 digits: the caller says what the number was.
#include <charconv>
#include <cstdint>
#include <optional>
#include <string_view>

namespace speckle {

// The non-negative integer `text` spells (digits only), or nothing when it is
// empty, holds anything else, or exceeds `max`.
inline std::optional<std::int64_t> ParseDecimal(std::string_view text, std::int64_t max = INT64_MAX) {
  std::int64_t value = 0;
  if (text.empty() || text.front() == '-' || text.front() == '+') return std::nullopt;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || value > max) return std::nullopt;
  return value;
}

}  // namespace speckle
