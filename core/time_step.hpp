// Stable time step of the mesh.
//
// Bound: with the lumped mass of every node split among its tets (any split with positive shares
// works), ω_max² of the assembled mesh ≤ max over tets of λ_max(M_e⁻¹K_e), because
// uᵀKu = Σ uₑᵀKₑuₑ ≤ Σ ω_e² uₑᵀMₑuₑ ≤ max ω_e² · uᵀMu.  Splitting each node's mass in proportion to
// the stiffness of its tets gives small stiff tets the mass of their softer neighbours, which keeps
// the bound close to the true limit on distorted meshes (the plain ρV/4 split is too pessimistic).
#pragma once

#include "core/model.hpp"

namespace fdem {

struct CriticalStep {
  double dt = 0.0;  // s
  LocalIndex limiting_tet = -1;
};

// Uses the current shape of each tet with the small-strain stiffness of its material.
CriticalStep critical_time_step(const Model& model);

// A lower bound of critical_time_step(model).dt (s) without its eigenvalue problems (~10× cheaper):
// for an isotropic tet, λ_max(M⁻¹K) = V·λ_max of a 3×3 problem built from G = Σ g_a g_aᵀ / m_a (g_a
// the shape gradients, m_a the corner masses), bounded above by Weyl's and Samuelson's
// inequalities; the corner masses of the stiffness-weighted split are bounded below with bounds of
// the weights. Infinity without tets.
double critical_time_step_lower_bound(const Model& model);

}  // namespace fdem
