// Range-checked float → integer conversions.  A cast of a double outside the target's range (or
// of NaN) is undefined behaviour in C++; every such conversion in fdem goes through these, so a
// huge or non-finite value becomes a message instead (UBSan's float-cast-overflow checks it).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

namespace fdem {

// True when `value` is finite and `static_cast<Int>(value)` is defined (the truncated value is
// in range).  The bounds ±2^digits are powers of two, exact in double.
template <class Int>
bool fits_integer(double value) {
  static_assert(std::numeric_limits<Int>::is_integer, "integer target");
  if (!std::isfinite(value)) return false;
  constexpr int digits = std::numeric_limits<Int>::digits;  // value bits (without the sign)
  const double upper = std::ldexp(1.0, digits);             // max + 1
  if (std::numeric_limits<Int>::is_signed) return std::trunc(value) >= -upper && value < upper;
  return value > -1.0 && value < upper;
}

// static_cast<Int>(value) when defined (truncation toward zero), otherwise nothing.
template <class Int>
std::optional<Int> to_integer(double value) {
  if (!fits_integer<Int>(value)) return std::nullopt;
  return static_cast<Int>(value);
}

// floor(value) as Int when defined, otherwise nothing.
template <class Int>
std::optional<Int> floor_to_integer(double value) {
  return to_integer<Int>(std::floor(value));
}

}  // namespace fdem
