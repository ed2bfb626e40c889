// Initial (in-situ) stress of the tets (scene key `initial_stress:`): a uniform tensor, or the
// geostatic state σ_v = −ρ|g|·depth along gravity and σ_h = K0·σ_v across it, evaluated at each
// tet's reference centroid (ρ its material's).  The stress is the tet's second Piola–Kirchhoff
// stress S0 at t = 0 (= the Cauchy stress there), carried with the material: the tet adds the
// first Piola stress F·S0 to its material's, and S0:E (E the Green strain) to the strain energy —
// the exact potential of F·S0 — so the balance stays exact and a rigid rotation leaves the stress
// turned with the body.  S0 follows from the scene and x0, so it is computed again after every
// redistribution and on a restart (nothing in checkpoints).
#pragma once

#include <vector>

#include "core/model.hpp"
#include "core/scene.hpp"

namespace fdem {

// S0 of every local tet (6 per tet: xx, yy, zz, yz, xz, xy; Pa, tension positive); zeros for a
// tet of a body without an entry.  `gravity` (m/s²) sets the geostatic direction and magnitude.
std::vector<double> initial_stresses(const std::vector<InitialStressSpec>& specs,
                                     const Vec3& gravity, const Model& model);

struct InitialStressForces {
  double energy = 0.0;  // J, Σ V0·S0:E over the owned tets
};

// Adds each active tet's −V0·(F·S0)·Dm⁻ᵀ to its nodes' forces, in model.tet_force_order (ascending
// tet gid: the same sum on any rank count).  Inverted tets are left to the elastic kernel's check.
InitialStressForces add_initial_stress_forces(const std::vector<double>& s0, Model& model);

// Equilibrium at t = 0: |Σ forces| over the free components of the owned nodes, in squares, and
// the same of the initial stress's forces alone (N²) — √(residual/scale) is the relative residual.
struct EquilibriumSums {
  double residual = 0.0, scale = 0.0;
};
EquilibriumSums equilibrium_sums(const std::vector<double>& total_force,
                                 const std::vector<double>& stress_force, const NodeArrays& nodes);

}  // namespace fdem
