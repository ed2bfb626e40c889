// Joint strength heterogeneity (scene key `fracture.strength_distribution`,
// docs/fracture-model.md §10): each joint's tensile strength and cohesion are the block's values
// times a factor drawn from a distribution of mean 1.
//
// The draw is a pure function of (seed, joint index): u = splitmix64 of the pair mapped to
// (0, 1), then the inverse CDF.  The joint index is its gid − gid_offset, which the serial and the
// distributed start-up give alike, so any rank count, order of discovery or gid offset gives each
// joint the same strength, and a restart recomputes it.  Factors are rounded to bins of ratio
// 1.01 (at most 0.5 % off) so that the joints share a few hundred laws instead of one each.
#pragma once

#include <cstdint>

#include "core/scene.hpp"

namespace fdem {

// Uniform in (0, 1), never 0 or 1, from (seed, index): element `index` of the splitmix64 stream
// seeded by `seed`.
double joint_uniform(std::uint64_t seed, std::uint64_t index);

// The factor at probability u of a distribution of mean 1: Weibull of modulus m (scale
// 1/Γ(1 + 1/m)), or normal of standard deviation cov cut at 0; kept within
// [min_strength_factor, 1/min_strength_factor].
double strength_factor(const StrengthDistributionSpec& d, double u);

// A joint weaker than this fraction of the block's strength is as good as broken; the bounds
// also bound the number of bins (ln(1000)/ln(1.01) ≈ 694 each side of 1).  Neither binds for
// the reader's ranges (modulus ≥ 1: largest factor 36.7; cov ≤ 0.3) but in the far lower tail.
constexpr double min_strength_factor = 1e-3;

// The strength bin of joint `index` (gid − gid_offset): round(ln factor / ln 1.01); 0 for a block
// without a distribution.
long strength_bin(const StrengthDistributionSpec& d, std::uint64_t index);

// The factor of a bin: 1.01^bin (1 for bin 0).
double strength_bin_factor(long bin);

// Φ⁻¹(p) of the standard normal distribution, 0 < p < 1 (relative error ~1e-15).
double inverse_normal_cdf(double p);

}  // namespace fdem
