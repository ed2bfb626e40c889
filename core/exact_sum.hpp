// An exact sum of doubles, rounded once when read: the same double whatever the order of the
// additions and however they are split into partial sums and merged.  Per-piece sums for
// bodies.csv use it, so that a piece's motion does not depend on how its nodes are spread over
// ranks (docs/parallel.md, "Pieces").
//
// The sum is held as an integer multiple of 2^-1074 (the smallest subnormal) in base-2^32 digits
// stored in 64-bit limbs, only over the span of digits the added values reach: a few limbs for
// values of similar magnitude.  Carries are propagated every 2^29 additions (limbs stay < 2^62).
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
  // Limbs in place up to 8 (256 bits: values within ~2^200 of each other), beyond that on the
  // heap: the per-piece sums of a frame allocate nothing.
  class Limbs {
   public:
    std::size_t size() const { return size_; }
    bool empty() const { return size_ == 0; }
    std::int64_t* begin() { return heap_.empty() ? in_place_ : heap_.data(); }
    const std::int64_t* begin() const { return heap_.empty() ? in_place_ : heap_.data(); }
    std::int64_t* end() { return begin() + size_; }
    const std::int64_t* end() const { return begin() + size_; }
    std::int64_t& operator[](std::size_t i) { return begin()[i]; }
    std::int64_t operator[](std::size_t i) const { return begin()[i]; }
    std::int64_t back() const { return begin()[size_ - 1]; }
    void resize(std::size_t n);  // new limbs are 0
    void push_back(std::int64_t limb);
    void pop_back() { --size_; }
    void grow_front(std::size_t n);  // n zero limbs before the first
    void drop_front(std::size_t n);

   private:
    static constexpr std::size_t in_place_count = 8;
    std::int64_t in_place_[in_place_count] = {};
    std::vector<std::int64_t> heap_;  // in use when not empty
    std::size_t size_ = 0;
  };

  void normalise();  // every limb but the top in [0, 2^32), no zero limb at either end
  ExactSum magnitude(bool* negative) const;  // normalised, every limb a digit in [0, 2^32)
  void reach(std::int32_t digit);            // widen the limbs to hold `digit`

  std::int32_t first_digit_ = 0;   // digit index of limbs_[0]
  Limbs limbs_;                    // limbs_[i]: the count of 2^(32·(first_digit_ + i) − 1074)
  std::int32_t unnormalised_ = 0;  // additions since the last normalise()
  std::uint8_t non_finite_ = 0;    // bit 0: +inf added, bit 1: −inf, bit 2: NaN
};

}  // namespace fdem
