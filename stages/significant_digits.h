#pragma once
// Rounding to significant digits, where a value's last bits are noise that
// must not reach an artifact or a comparison (see the callers).
#include <cmath>

namespace speckle {

inline double RoundToSignificantDigits(double value, int digits) {
  if (value == 0 || !std::isfinite(value)) return value;
  const double unit = std::pow(10.0, std::floor(std::log10(std::abs(value))) - (digits - 1));
  return std::round(value / unit) * unit;
}

}  // namespace speckle
