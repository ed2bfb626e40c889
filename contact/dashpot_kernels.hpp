// The normal contact dashpot of one overlapping pair: a force −c·v_n along the normal at the
// overlap centroid, never pulling harder than the elastic push.  Pure functions.
//
// Sized by the bodies (the default): a block landing on its heel bounces on the few tet pairs
// under its edge, whose stiffness carries the whole block's momentum.  A dashpot sized by the two
// tets' masses, c = 2ξ√(k·m_tets), damps the tets' own vibration on that contact but leaves the
// block's bounce almost undamped (its damping ratio there is ξ√(n·m_tets/M) for n pairs carrying
// a block of mass M).  Sized by the two pieces' reduced mass M instead, c = 2ξ√(k·M), one pair
// alone damps the bounce by ξ and n pairs together by ξ to ξ√n.
//
// Such a dashpot is far stronger than the tets' own mass can follow in one explicit step (the
// pair's local mass m_loc, at the centroid, is a tet's), so it acts implicitly on the pair's local
// degree of freedom: c_eff = c / (1 + c·Δt / (κ·m_loc)).  In one step it removes at most the share
// κ of the pair's relative normal velocity (κ = 1/2: a node shared by several pairs stays far
// from the explicit limit of 2), whatever c; for a weak dashpot (c·Δt ≪ m_loc) c_eff = c.
#pragma once

#include <cmath>

#include "contact/potential_contact_kernels.hpp"

namespace fdem {

// Largest share of the pair's relative normal velocity the dashpot removes in one step.
inline constexpr double kDashpotStepShare = 0.5;

// Reduced mass (kg) of two partners; a fixed one has infinite mass.
inline double reduced_mass(double m_a, bool a_fixed, double m_b, bool b_fixed) {
  return a_fixed ? m_b : b_fixed ? m_a : m_a * m_b / (m_a + m_b);
}

// Mass (kg) of the pair's point at the overlap centroid: 1/m_loc = Σ w²/m over the corners of
// both tets, `inverse_node_mass` 0 for a fixed node.
inline double centroid_point_mass(const ContactPairResult& r, const double (&inverse_mass_a)[4],
                                  const double (&inverse_mass_b)[4]) {
  double inverse = 0.0;
  for (int c = 0; c < 4; ++c)
    inverse +=
        r.centroid_weights_contactor[c] * r.centroid_weights_contactor[c] * inverse_mass_a[c] +
        r.centroid_weights_target[c] * r.centroid_weights_target[c] * inverse_mass_b[c];
  return inverse > 0.0 ? 1.0 / inverse : 0.0;
}

// Dashpot coefficient (N·s/m) sized by `mass` (kg) on the pair's secant stiffness k (N/m), made
// implicit on the pair's local mass m_loc (kg) when `local_mass` > 0 (else explicit, as sized).
inline double dashpot_coefficient(double xi, double k, double mass, double local_mass, double dt) {
  const double c = 2.0 * xi * std::sqrt(k * mass);
  if (!(local_mass > 0.0)) return c;
  return c / (1.0 + c * dt / (kDashpotStepShare * local_mass));
}

}  // namespace fdem
