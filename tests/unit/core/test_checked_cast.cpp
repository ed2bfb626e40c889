// Range-checked float → integer conversions (core/checked_cast.hpp).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/checked_cast.hpp"

using fdem::fits_integer;
using fdem::floor_to_integer;
using fdem::to_integer;

TEST_CASE("float to integer conversions are refused outside the target's range", "[checked]") {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(fits_integer<int>(2147483647.0));
  CHECK(fits_integer<int>(2147483647.9));  // truncates to INT_MAX
  CHECK_FALSE(fits_integer<int>(2147483648.0));
  CHECK(fits_integer<int>(-2147483648.0));
  CHECK(fits_integer<int>(-2147483648.5));  // truncates to INT_MIN
  CHECK_FALSE(fits_integer<int>(-2147483649.0));
  CHECK_FALSE(fits_integer<long>(1e300));
  CHECK_FALSE(fits_integer<long>(9223372036854775808.0));  // 2^63
  CHECK(fits_integer<long>(9223372036854774784.0));        // largest double below 2^63
  CHECK_FALSE(fits_integer<std::int64_t>(inf));
  CHECK_FALSE(fits_integer<std::int64_t>(-inf));
  CHECK_FALSE(fits_integer<std::int64_t>(nan));
  CHECK(fits_integer<unsigned>(-0.5));  // truncates to 0
  CHECK_FALSE(fits_integer<unsigned>(-1.0));
  CHECK_FALSE(fits_integer<std::uint64_t>(18446744073709551616.0));  // 2^64
}

TEST_CASE("to_integer truncates and floor_to_integer floors when in range", "[checked]") {
  CHECK(to_integer<int>(-2.7) == -2);
  CHECK(floor_to_integer<int>(-2.7) == -3);
  CHECK(floor_to_integer<std::int64_t>(1.8e19) == std::nullopt);
  CHECK(floor_to_integer<std::int64_t>(-1.8e19) == std::nullopt);
  CHECK(to_integer<long>(816502086734029.0) == 816502086734029L);
}
