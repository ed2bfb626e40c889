// ExactSum: the correctly rounded sum whatever the order, split and merge of the additions
// (known cases: ties to even, cancellation, subnormals, overflow; random values against an exact
// 128-bit integer sum), words that read back to the same sum, non-finite values; PieceTable:
// ids body by body, kept pieces.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "core/exact_sum.hpp"
#include "core/model.hpp"

using namespace fdem;

namespace {

double sum_of(const std::vector<double>& values) {
  ExactSum s;
  for (double v : values) s.add(v);
  return s.value();
}

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

}  // namespace

TEST_CASE("ExactSum: known sums, rounded once to nearest, ties to even", "[core][exact_sum]") {
  CHECK(sum_of({}) == 0.0);
  CHECK(!std::signbit(sum_of({1.5, -1.5})));
  CHECK(sum_of({0.1, 0.2}) == 0.1 + 0.2);  // one rounding: the plain sum is correctly rounded
  const double two53 = 9007199254740992.0;
  CHECK(sum_of({two53, 1.0}) == two53);                // tie: down to the even mantissa
  CHECK(sum_of({two53, 1.0, 2.0}) == two53 + 4.0);     // 2^53 + 3: up to the even one
  CHECK(sum_of({two53, 1.0, 1e-300}) == two53 + 2.0);  // just above the tie: up
  CHECK(sum_of({1e300, 1.0, -1e300}) == 1.0);          // the plain sum gives 0
  CHECK(sum_of({1e308, 1e308, -1e308}) == 1e308);      // the plain sum overflows
  CHECK(sum_of({1e308, 1e308}) == std::numeric_limits<double>::infinity());
  CHECK(sum_of({-1e308, -1e308}) == -std::numeric_limits<double>::infinity());
  const double tiny = std::numeric_limits<double>::denorm_min();
  CHECK(sum_of({tiny, tiny, tiny}) == 3 * tiny);
  CHECK(sum_of({1.0, tiny, -1.0}) == tiny);
  CHECK(sum_of({-2.5, 0.25, -0.125}) == -2.375);
  CHECK(sum_of({std::ldexp(1.0, 600), -std::ldexp(1.0, -600), -std::ldexp(1.0, 600)}) ==
        -std::ldexp(1.0, -600));
}

TEST_CASE("ExactSum: non-finite values combine as a plain sum, in any order", "[core][exact_sum]") {
  const double inf = std::numeric_limits<double>::infinity();
  CHECK(sum_of({1.0, inf, 2.0}) == inf);
  CHECK(sum_of({-inf, 1e308, 1e308}) == -inf);
  CHECK(std::isnan(sum_of({inf, 1.0, -inf})));
  CHECK(std::isnan(sum_of({std::nan(""), 1.0})));
}

TEST_CASE("ExactSum: random values equal the exact integer sum rounded", "[core][exact_sum]") {
  // Values k·2^-40 with |k| < 2^62: their exact sum fits 128 bits; GCC converts it correctly.
  __extension__ typedef __int128 wide;
  std::mt19937_64 random(7);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<double> values;
    wide exact = 0;
    const int count = 1 + trial * 5;
    for (int i = 0; i < count; ++i) {
      const int bits = static_cast<int>(random() % 53);  // a 53-bit mantissa at most
      std::int64_t k = static_cast<std::int64_t>(random() >> (64 - bits - 1)) >> 1;
      k <<= random() % 9;  // up to 2^61
      if (random() & 1) k = -k;
      values.push_back(std::ldexp(static_cast<double>(k), -40));
      REQUIRE(std::ldexp(values.back(), 40) == static_cast<double>(k));  // exact
      exact += k;
    }
    const double expected = std::ldexp(static_cast<double>(exact), -40);
    CHECK(same_bits(sum_of(values), expected));
  }
}

TEST_CASE("ExactSum: the same bits for any order, split, merge and word round trip",
          "[core][exact_sum]") {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::vector<double> values;
  for (int i = 0; i < 5000; ++i)  // exponents from 2^-1070 to 2^1000
    values.push_back(std::ldexp(mantissa(random), static_cast<int>(random() % 2070) - 1070));
  const double whole = sum_of(values);
  for (int trial = 0; trial < 20; ++trial) {
    std::shuffle(values.begin(), values.end(), random);
    // Split among "ranks", each partial sent as words and merged at a "directory".
    const std::size_t parts = 1 + random() % 7;
    std::vector<ExactSum> partial(parts);
    for (double v : values) partial[random() % parts].add(v);
    std::vector<std::int64_t> words;
    for (const ExactSum& p : partial) p.append_words(words);
    ExactSum merged;
    const std::int64_t* w = words.data();
    for (std::size_t p = 0; p < parts; ++p) merged.add(ExactSum::from_words(w));
    CHECK(w == words.data() + words.size());
    CHECK(same_bits(merged.value(), whole));
  }
}

TEST_CASE("PieceTable: ids body by body, kept pieces", "[core][pieces]") {
  PieceTable pieces;
  pieces.add_body(3);
  pieces.add_body(0);
  pieces.add_body(2);
  CHECK(pieces.size() == 5);
  CHECK(pieces.bodies() == 3);
  CHECK(pieces.body_of(0) == 0);
  CHECK(pieces.body_of(2) == 0);
  CHECK(pieces.body_of(3) == 2);  // body 1 has no piece
  CHECK(pieces.index_in_body(4) == 1);
  CHECK(pieces.pieces_in_body(1) == 0);
  CHECK(pieces.kept().empty());
  pieces.keep_range(1, 3);
  pieces.keep({0, 2, 4});
  CHECK(pieces.kept() == std::vector<std::int32_t>{0, 1, 2, 4});
  CHECK(pieces[4].body == 2);
  CHECK(pieces[4].index_in_body == 1);
  pieces[2].mass = 7.0;
  pieces.keep_only_range(2, 5);
  CHECK(pieces.kept() == std::vector<std::int32_t>{2, 4});
  CHECK(pieces[2].mass == 7.0);
  CHECK(!pieces.keeps(1));
  CHECK_THROWS(pieces[1]);
}
