#include "core/exact_sum.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/error.hpp"

namespace fdem {

namespace {
constexpr std::int64_t digit_base = std::int64_t{1} << 32;
// Carries are propagated before a limb could hold 2^30 additions of up to 2^32 each (< 2^62).
constexpr std::int32_t additions_before_normalising = std::int32_t{1} << 29;
constexpr std::uint8_t plus_infinity = 1, minus_infinity = 2, not_a_number = 4;

std::int64_t floor_div_base(std::int64_t v) {
  return v >= 0 ? v / digit_base : -((-(v + 1)) / digit_base) - 1;
}
}  // namespace

void ExactSum::Limbs::resize(std::size_t n) {
  if (heap_.empty() && n > in_place_count) {
    heap_.assign(n, 0);
    std::copy(in_place_, in_place_ + size_, heap_.begin());
  } else if (!heap_.empty() && heap_.size() < n) {
    heap_.resize(n, 0);
  }
  std::fill(begin() + std::min(size_, n), begin() + n, 0);
  size_ = n;
}

void ExactSum::Limbs::push_back(std::int64_t limb) {
  resize(size_ + 1);
  begin()[size_ - 1] = limb;
}

void ExactSum::Limbs::grow_front(std::size_t n) {
  const std::size_t old = size_;
  resize(size_ + n);
  std::move_backward(begin(), begin() + old, begin() + old + n);
  std::fill(begin(), begin() + n, 0);
}

void ExactSum::Limbs::drop_front(std::size_t n) {
  std::move(begin() + n, end(), begin());
  size_ -= n;
}

void ExactSum::reach(std::int32_t digit) {
  if (limbs_.empty()) {
    first_digit_ = digit;
    limbs_.resize(1);
  } else if (digit < first_digit_) {
    limbs_.grow_front(static_cast<std::size_t>(first_digit_ - digit));
    first_digit_ = digit;
  } else if (digit >= first_digit_ + static_cast<std::int32_t>(limbs_.size())) {
    limbs_.resize(static_cast<std::size_t>(digit - first_digit_ + 1));
  }
}

void ExactSum::add(double x) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &x, sizeof bits);
  const bool negative = (bits >> 63) != 0;
  const int exponent = static_cast<int>((bits >> 52) & 0x7ff);
  std::uint64_t mantissa = bits & ((std::uint64_t{1} << 52) - 1);
  if (exponent == 0x7ff) {
    non_finite_ |= mantissa != 0 ? not_a_number : negative ? minus_infinity : plus_infinity;
    return;
  }
  if (exponent == 0 && mantissa == 0) return;
  // x = mantissa · 2^(position − 1074): subnormals at position 0, normals at exponent − 1.
  int position = 0;
  if (exponent != 0) {
    mantissa |= std::uint64_t{1} << 52;
    position = exponent - 1;
  }
  __extension__ typedef unsigned __int128 wide;
  const wide shifted = static_cast<wide>(mantissa) << (position % 32);  // < 2^85: three digits
  const std::int32_t digit = position / 32;
  const std::int64_t chunk[3] = {static_cast<std::int64_t>(shifted & 0xffffffffu),
                                 static_cast<std::int64_t>((shifted >> 32) & 0xffffffffu),
                                 static_cast<std::int64_t>(shifted >> 64)};
  int low = 0, high = 2;
  while (chunk[low] == 0) ++low;
  while (chunk[high] == 0) --high;
  reach(digit + low);
  reach(digit + high);
  for (int k = low; k <= high; ++k) {
    std::int64_t& limb = limbs_[static_cast<std::size_t>(digit + k - first_digit_)];
    limb += negative ? -chunk[k] : chunk[k];
  }
  if (++unnormalised_ >= additions_before_normalising) normalise();
}

void ExactSum::add(const ExactSum& other) {
  non_finite_ |= other.non_finite_;
  if (other.limbs_.empty()) return;
  reach(other.first_digit_);
  reach(other.first_digit_ + static_cast<std::int32_t>(other.limbs_.size()) - 1);
  const std::size_t offset = static_cast<std::size_t>(other.first_digit_ - first_digit_);
  for (std::size_t i = 0; i < other.limbs_.size(); ++i) limbs_[offset + i] += other.limbs_[i];
  unnormalised_ += other.unnormalised_ + 1;
  if (unnormalised_ >= additions_before_normalising) normalise();
}

void ExactSum::normalise() {
  unnormalised_ = 0;
  std::int64_t carry = 0;
  for (std::int64_t& limb : limbs_) {
    const std::int64_t v = limb + carry;
    carry = floor_div_base(v);
    limb = v - carry * digit_base;
  }
  // The carry out of the top becomes further digits; the last one keeps the sign.
  while (carry <= -digit_base || carry >= digit_base) {
    const std::int64_t v = carry;
    carry = floor_div_base(v);
    limbs_.push_back(v - carry * digit_base);
  }
  if (carry != 0) limbs_.push_back(carry);
  while (!limbs_.empty() && limbs_.back() == 0) limbs_.pop_back();
  std::size_t zeros = 0;
  while (zeros < limbs_.size() && limbs_[zeros] == 0) ++zeros;
  limbs_.drop_front(zeros);
  first_digit_ = limbs_.empty() ? 0 : first_digit_ + static_cast<std::int32_t>(zeros);
}

double ExactSum::value() const {
  if (non_finite_ != 0) {
    const bool nan =
        (non_finite_ & not_a_number) != 0 ||
        (non_finite_ & (plus_infinity | minus_infinity)) == (plus_infinity | minus_infinity);
    if (nan) return std::numeric_limits<double>::quiet_NaN();
    return (non_finite_ & plus_infinity) ? std::numeric_limits<double>::infinity()
                                         : -std::numeric_limits<double>::infinity();
  }
  bool negative = false;
  const ExactSum m = magnitude(&negative);
  if (m.limbs_.empty()) return 0.0;
  const auto digit = [&](std::int64_t d) -> std::uint64_t {
    const std::int64_t i = d - m.first_digit_;
    return i < 0 || i >= static_cast<std::int64_t>(m.limbs_.size())
               ? 0
               : static_cast<std::uint64_t>(m.limbs_[static_cast<std::size_t>(i)]);
  };
  const auto bit = [&](std::int64_t k) -> std::uint64_t { return (digit(k >> 5) >> (k & 31)) & 1; };
  const std::int64_t top_digit = m.first_digit_ + static_cast<std::int64_t>(m.limbs_.size()) - 1;
  const std::int64_t length =
      32 * top_digit + 64 - __builtin_clzll(static_cast<std::uint64_t>(m.limbs_.back()));
  double magnitude = 0.0;
  if (length <= 53) {  // exact: below 2^53 units of 2^-1074
    std::uint64_t v = 0;
    for (std::int64_t k = 0; k < length; ++k) v |= bit(k) << k;
    magnitude = std::ldexp(static_cast<double>(v), -1074);
  } else {  // the top 53 bits, rounded to nearest, ties to even
    const std::int64_t shift = length - 53;
    std::uint64_t top = 0;
    for (std::int64_t k = 0; k < 53; ++k) top |= bit(shift + k) << k;
    const bool half = bit(shift - 1) != 0;
    bool below_half = false;  // any bit under the half bit
    const std::int64_t half_position = shift - 1;
    for (std::int64_t d = m.first_digit_; d <= (half_position >> 5) && !below_half; ++d) {
      std::uint64_t bits = digit(d);
      if (d == (half_position >> 5)) bits &= (std::uint64_t{1} << (half_position & 31)) - 1;
      below_half = bits != 0;
    }
    if (half && (below_half || (top & 1))) ++top;
    magnitude = std::ldexp(static_cast<double>(top), static_cast<int>(shift - 1074));
  }
  return negative ? -magnitude : magnitude;
}

ExactSum ExactSum::magnitude(bool* negative) const {
  ExactSum m = *this;
  m.normalise();
  // The top limb carries the sign (the others are digits in [0, 2^32)).
  *negative = !m.limbs_.empty() && m.limbs_.back() < 0;
  if (*negative) {
    for (std::int64_t& limb : m.limbs_) limb = -limb;
    m.normalise();
  }
  return m;
}

// Header word: first digit (bits 0–15), digit count (16–31), sign (32), non-finite flags (33–35).
void ExactSum::append_words(std::vector<std::int64_t>& out) const {
  bool negative = false;
  const ExactSum m = magnitude(&negative);
  const std::uint64_t count = m.limbs_.size();
  out.push_back(static_cast<std::int64_t>(static_cast<std::uint64_t>(m.first_digit_) | count << 16 |
                                          std::uint64_t{negative} << 32 |
                                          std::uint64_t{non_finite_} << 33));
  for (std::size_t i = 0; i < count; i += 2) {
    const std::uint64_t high = i + 1 < count ? static_cast<std::uint64_t>(m.limbs_[i + 1]) : 0;
    out.push_back(static_cast<std::int64_t>(static_cast<std::uint64_t>(m.limbs_[i]) | high << 32));
  }
}

ExactSum ExactSum::from_words(const std::int64_t*& words) {
  const std::uint64_t header = static_cast<std::uint64_t>(*words++);
  ExactSum s;
  s.first_digit_ = static_cast<std::int32_t>(header & 0xffff);
  const std::size_t count = (header >> 16) & 0xffff;
  FDEM_VERIFY(count <= 80 && header >> 36 == 0, "an exact sum read from words is well formed");
  const bool negative = (header >> 32) & 1;
  s.non_finite_ = static_cast<std::uint8_t>((header >> 33) & 7);
  s.limbs_.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint64_t word = static_cast<std::uint64_t>(words[i / 2]);
    const std::int64_t digit = static_cast<std::int64_t>(i % 2 ? word >> 32 : word & 0xffffffffu);
    s.limbs_[i] = negative ? -digit : digit;
  }
  words += (count + 1) / 2;
  return s;
}

}  // namespace fdem
