// The normal contact dashpot's coefficient (contact/dashpot_kernels.hpp).
#include <catch2/catch.hpp>
#include <cmath>

#include "contact/dashpot_kernels.hpp"

using namespace fdem;

TEST_CASE(
    "dashpot coefficient: 2ξ√(k·m) explicit, the same while weak, at most the step share "
    "of the local mass when strong",
    "[contact][dashpot]") {
  const double xi = 0.3, k = 4e9, dt = 1e-6;
  // Explicit (no local mass): the sized coefficient itself.
  CHECK(dashpot_coefficient(xi, k, 2.0, 0.0, dt) == Approx(2 * xi * std::sqrt(k * 2.0)));
  // Weak against the local mass (c·Δt = 1e-4·m_loc): within 2.1e-4 of it.
  const double weak = 2 * xi * std::sqrt(k * 2.0);
  const double local = weak * dt / 1e-4;
  CHECK(dashpot_coefficient(xi, k, 2.0, local, dt) == Approx(weak).epsilon(2.1e-4));
  CHECK(dashpot_coefficient(xi, k, 2.0, local, dt) < weak);
  // Strong (a body of 1e6 kg on a 1 kg local mass): one step removes less than the share κ of
  // the pair's relative normal velocity, and tends to it.
  const double strong = dashpot_coefficient(xi, k, 1e6, 1.0, dt);
  CHECK(strong * dt / 1.0 < kDashpotStepShare);
  CHECK(strong * dt / 1.0 > 0.98 * kDashpotStepShare);  // c·Δt/(κ·m_loc) = 76 here
  // Monotonic in the sizing mass.
  CHECK(dashpot_coefficient(xi, k, 10.0, 1.0, dt) < dashpot_coefficient(xi, k, 100.0, 1.0, dt));
}

TEST_CASE(
    "dashpot masses: a fixed partner has infinite mass and the centroid point has the mass "
    "its weights give",
    "[contact][dashpot]") {
  CHECK(reduced_mass(2.0, false, 6.0, false) == Approx(1.5));
  CHECK(reduced_mass(2.0, true, 6.0, false) == 6.0);
  CHECK(reduced_mass(2.0, false, 6.0, true) == 2.0);
  ContactPairResult r;
  for (int c = 0; c < 4; ++c) r.centroid_weights_contactor[c] = r.centroid_weights_target[c] = 0.25;
  // Four 1 kg nodes per side at equal weights: each side is a 4 kg point, together 2 kg.
  const double unit[4] = {1.0, 1.0, 1.0, 1.0}, none[4] = {0.0, 0.0, 0.0, 0.0};
  CHECK(centroid_point_mass(r, unit, unit) == Approx(2.0));
  CHECK(centroid_point_mass(r, unit, none) == Approx(4.0));  // the target fixed
  // All weight on one node of 3 kg, the other side fixed: that node.
  for (int c = 0; c < 4; ++c) r.centroid_weights_contactor[c] = c == 2 ? 1.0 : 0.0;
  const double nodes[4] = {1.0, 1.0, 1.0 / 3.0, 1.0};
  CHECK(centroid_point_mass(r, nodes, none) == Approx(3.0));
  CHECK(centroid_point_mass(r, none, none) == 0.0);  // both fixed: no local mass
}
