#include "core/joint_strength.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace fdem {

namespace {

constexpr std::uint64_t golden_gamma = 0x9E3779B97F4A7C15ull;  // splitmix64's increment
constexpr double strength_bin_ratio = 1.01;

// The splitmix64 output function (Steele, Lea & Flood 2014).
std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Standard normal CDF.
double normal_cdf(double x) {
  return 0.5 * std::erfc(-x / std::sqrt(2.0));
}

}  // namespace

double joint_uniform(std::uint64_t seed, std::uint64_t index) {
  // Element `index` of the stream whose state starts at mix64(seed): a counter-based draw, so
  // no joint's value depends on how many were drawn before it.
  const std::uint64_t bits = mix64(mix64(seed) + (index + 1) * golden_gamma);
  // The top 52 bits + ½ over 2^52: in [2^-53, 1 − 2^-53], exact in a double.
  return (static_cast<double>(bits >> 12) + 0.5) * 0x1p-52;
}

double inverse_normal_cdf(double p) {
  FDEM_VERIFY(p > 0.0 && p < 1.0, "a probability strictly between 0 and 1");
  // Acklam's rational approximation (relative error 1.15e-9), then one Halley step on erfc.
  static const double a[6] = {-3.969683028665376e+01, 2.209460984245205e+02,
                              -2.759285104469687e+02, 1.383577518672690e+02,
                              -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[5] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                              6.680131188771972e+01, -1.328068155288572e+01};
  static const double c[6] = {-7.784894002430293e-03, -3.223964580411365e-01,
                              -2.400758277161838e+00, -2.549732539343734e+00,
                              4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[4] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                              3.754408661907416e+00};
  const double low = 0.02425;
  double x;
  const auto tail = [&](double q) {
    return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
           ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  };
  if (p < low) {
    x = tail(std::sqrt(-2.0 * std::log(p)));
  } else if (p > 1.0 - low) {
    x = -tail(std::sqrt(-2.0 * std::log1p(-p)));
  } else {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
  }
  const double e = normal_cdf(x) - p;
  const double u = e * std::sqrt(2.0 * M_PI) * std::exp(0.5 * x * x);
  return x - u / (1.0 + 0.5 * x * u);
}

double strength_factor(const StrengthDistributionSpec& d, double u) {
  double s = 1.0;
  switch (d.type) {
    case StrengthDistributionSpec::Type::none:
      return 1.0;
    case StrengthDistributionSpec::Type::weibull:
      // F(s) = 1 − exp(−(s/λ)^m) with λ = 1/Γ(1 + 1/m), so that the mean is 1.
      s = std::pow(-std::log1p(-u), 1.0 / d.modulus) / std::tgamma(1.0 + 1.0 / d.modulus);
      break;
    case StrengthDistributionSpec::Type::normal: {
      // Normal of mean 1 and deviation cov, cut at 0: u spans the part above 0.
      const double below_zero = normal_cdf(-1.0 / d.cov);
      const double p = std::min(below_zero + u * (1.0 - below_zero), 1.0 - 0x1p-53);
      s = 1.0 + d.cov * inverse_normal_cdf(p);
      break;
    }
  }
  return std::min(std::max(s, min_strength_factor), 1.0 / min_strength_factor);
}

long strength_bin(const StrengthDistributionSpec& d, std::uint64_t index) {
  if (d.type == StrengthDistributionSpec::Type::none) return 0;
  const double s = strength_factor(d, joint_uniform(d.seed, index));
  return std::lround(std::log(s) / std::log(strength_bin_ratio));
}

double strength_bin_factor(long bin) {
  return bin == 0 ? 1.0 : std::pow(strength_bin_ratio, static_cast<double>(bin));
}

}  // namespace fdem
