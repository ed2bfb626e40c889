// An exact sum of doubles, rounded once when read: the same double whatever the order of the
// additions and however they are split into partial sums and merged.  Per-piece sums for
// bodies.csv use it, so that a piece's motion does not depend on how its nodes are spread over
// ranks (docs/parallel.md, "Pieces").
//
// The sum is held as an integer multiple of 2^-1074 (the smallest subnormal) in base-2^32 digits
// stored in 64-bit limbs, only over the span of digits the added values reach: a few limbs for
// values of similar magnitude.  A limb absorbs 2^30 additions before carries are propagated.
#pragma once

#include <cstdint>
#include <vector>

namespace fdem {

class ExactSum {
 public:
  void add(double x);
  void add(const ExactSum& other);
  // The sum rounded to the nearest double (ties to even): +0 for an empty or zero sum, ±inf
  // beyond the double range; NaN or ±inf as a plain sum gives them when non-finite values were
  // added (those combine the same in any order).
  double value() const;

  // As 64-bit words, for messages: a header (first digit, digit count, sign, non-finite flags),
  // then the digits of the magnitude, two to a word.
  void append_words(std::vector<std::int64_t>& out) const;
  // Reads what append_words wrote at `words` and moves `words` past it.
  static ExactSum from_words(const std::int64_t*& words);

 private:
  void normalise();  // every limb but the top in [0, 2^32), no zero limb at either end
  ExactSum magnitude(bool* negative) const;  // normalised, every limb a digit in [0, 2^32)
  void reach(std::int32_t digit);            // widen the limbs to hold `digit`

  std::int32_t first_digit_ = 0;     // digit index of limbs_[0]
  std::vector<std::int64_t> limbs_;  // limbs_[i]: the count of 2^(32·(first_digit_ + i) − 1074)
  std::int32_t unnormalised_ = 0;    // additions since the last normalise()
  std::uint8_t non_finite_ = 0;      // bit 0: +inf added, bit 1: −inf, bit 2: NaN
};

}  // namespace fdem
