// Joint strength heterogeneity (core/joint_strength): the factors drawn for many joints have the
// distribution asked for — mean, spread, Weibull modulus fitted from the draws — and depend only
// on (seed, joint index).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "core/joint_strength.hpp"

using namespace fdem;

namespace {

constexpr std::uint64_t draws = 200000;

// The binned factors of joints 0..n−1, as the laws receive them.
std::vector<double> factors(const StrengthDistributionSpec& d, std::uint64_t n = draws) {
  std::vector<double> out(n);
  for (std::uint64_t i = 0; i < n; ++i) out[i] = strength_bin_factor(strength_bin(d, i));
  return out;
}

double mean_of(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

double deviation_of(const std::vector<double>& v) {
  const double m = mean_of(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

StrengthDistributionSpec weibull(double m, std::uint64_t seed) {
  StrengthDistributionSpec d;
  d.type = StrengthDistributionSpec::Type::weibull;
  d.modulus = m;
  d.seed = seed;
  return d;
}

StrengthDistributionSpec normal(double cov, std::uint64_t seed) {
  StrengthDistributionSpec d;
  d.type = StrengthDistributionSpec::Type::normal;
  d.cov = cov;
  d.seed = seed;
  return d;
}

}  // namespace

TEST_CASE("joint_uniform: in (0, 1), uniform, uncorrelated from one joint to the next",
          "[strength]") {
  double sum = 0.0, lag = 0.0, previous = 0.5, lowest = 1.0, highest = 0.0;
  long below_tenth = 0;
  for (std::uint64_t i = 0; i < draws; ++i) {
    const double u = joint_uniform(7, i);
    sum += u;
    lag += (u - 0.5) * (previous - 0.5);
    previous = u;
    lowest = std::min(lowest, u);
    highest = std::max(highest, u);
    below_tenth += u < 0.1;
  }
  CHECK(lowest > 0.0);
  CHECK(highest < 1.0);
  // Standard errors: mean 0.29/√n = 6.5e-4, fraction 0.3/√n = 6.7e-4, correlation 1/√n.
  CHECK(sum / draws == Approx(0.5).margin(0.003));
  CHECK(static_cast<double>(below_tenth) / draws == Approx(0.1).margin(0.003));
  CHECK(std::abs(lag / draws / (1.0 / 12.0)) < 0.01);
  // A pure function of (seed, index): the same value in any order; another seed, another value.
  CHECK(joint_uniform(7, 123456) == joint_uniform(7, 123456));
  CHECK(joint_uniform(8, 123456) != joint_uniform(7, 123456));
}

TEST_CASE("inverse_normal_cdf inverts Φ to round-off", "[strength]") {
  for (double p : {1e-12, 1e-6, 0.001, 0.02425, 0.1, 0.5, 0.7, 0.97575, 0.999, 1 - 1e-9}) {
    const double x = inverse_normal_cdf(p);
    const double back = 0.5 * std::erfc(-x / std::sqrt(2.0));
    INFO("p = " << p << ", x = " << x);
    CHECK(back == Approx(p).epsilon(1e-12));
  }
  CHECK(inverse_normal_cdf(0.5) == Approx(0.0).margin(1e-15));
  CHECK(inverse_normal_cdf(0.975) == Approx(1.959963984540054).epsilon(1e-14));
}

TEST_CASE("normal strength factors: mean 1 and deviation cov over 200 000 joints", "[strength]") {
  for (double cov : {0.05, 0.2, 0.3}) {
    const std::vector<double> s = factors(normal(cov, 42));
    INFO("cov " << cov);
    // Sampling errors: of the mean cov/√n ≤ 6.7e-4, of the deviation 1/√(2n) = 0.16 % of it;
    // the 1 % bins add (ln 1.01)²/12 = 8e-6 to the log-variance.
    CHECK(mean_of(s) == Approx(1.0).margin(0.003));
    CHECK(deviation_of(s) == Approx(cov).epsilon(0.01));
    CHECK(*std::min_element(s.begin(), s.end()) > 0.0);
  }
}

TEST_CASE("Weibull strength factors: mean 1, the modulus fitted from 200 000 joints",
          "[strength]") {
  for (double m : {1.0, 3.0, 8.0}) {
    std::vector<double> s = factors(weibull(m, 2024));
    INFO("modulus " << m);
    const double cov = std::sqrt(std::tgamma(1 + 2 / m) / std::pow(std::tgamma(1 + 1 / m), 2) - 1);
    CHECK(mean_of(s) == Approx(1.0).margin(3 * cov / std::sqrt(double(draws))));
    CHECK(deviation_of(s) == Approx(cov).epsilon(0.02));
    // Weibull plot: ln(−ln(1 − F)) against ln s is a line of slope m.  Least squares over the
    // 1st–99th percentiles of the sorted draws (median ranks F = (i + 0.7)/(n + 0.4)).
    std::sort(s.begin(), s.end());
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    long n = 0;
    for (std::size_t i = draws / 100; i < draws - draws / 100; ++i) {
      const double F = (static_cast<double>(i) + 0.7) / (static_cast<double>(draws) + 0.4);
      const double x = std::log(s[i]), y = std::log(-std::log1p(-F));
      sx += x;
      sy += y;
      sxx += x * x;
      sxy += x * y;
      ++n;
    }
    const double fitted = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    std::printf("  Weibull modulus %.1f: fitted %.4f, mean %.5f, cov %.4f (exact %.4f)\n", m,
                fitted, mean_of(s), deviation_of(s), cov);
    CHECK(fitted == Approx(m).epsilon(0.02));
  }
}

TEST_CASE("strength bins: factor within 0.5 % of the draw, none is exactly 1", "[strength]") {
  const StrengthDistributionSpec none;
  for (std::uint64_t i : {0ull, 1ull, 99999ull}) {
    CHECK(strength_bin(none, i) == 0);
  }
  CHECK(strength_bin_factor(0) == 1.0);
  const StrengthDistributionSpec d = weibull(3, 5);
  for (std::uint64_t i = 0; i < 1000; ++i) {
    const double exact = strength_factor(d, joint_uniform(d.seed, i));
    const double binned = strength_bin_factor(strength_bin(d, i));
    CHECK(std::abs(binned / exact - 1.0) <= 0.005);
  }
  // The floor: a draw in the far lower tail keeps a positive strength.
  CHECK(strength_factor(weibull(1, 0), 1e-300) == min_strength_factor);
}
