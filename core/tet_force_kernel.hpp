// The tetrahedron's internal force, written once for one tet (T = double) and for four side by
// side (T = Lanes, core/lanes.hpp), so the element loop can compute four tets per instruction and
// still give every tet the bits of the one-tet kernel (tested).  Constant-strain 4-node tet, total
// Lagrangian: F = Ds·Dm⁻¹ with Ds = [x1−x0, x2−x0, x3−x0]; 3 × 3 matrices as nine values,
// column-major (core/small_matrix.hpp).
#pragma once

#include <type_traits>

#include "core/lanes.hpp"
#include "core/materials.hpp"
#include "core/small_matrix.hpp"
#include "core/types.hpp"

namespace fdem {

template <class T>
struct TetCornerForces {
  T force[4][3];    // internal (elastic + viscous) force on each corner (N)
  T strain_energy;  // W(F)·V0 (J)
  T damping_power;  // viscous dissipation rate V0·P_v:Ḟ (W), ≥ 0
  T jacobian;       // det F; ≤ 0 means the element inverted (forces zero)
};

// x, v: corner positions (m) and velocities (m/s), corner by corner; dm_inv (1/m); volume0 (m³);
// viscosity η (Pa·s) adds the viscous Cauchy stress 2η·sym(ḞF⁻¹) where η > 0.  `any_viscous`:
// some element has η > 0 (else velocities are not read).  Inverted elements (det F ≤ 0 or NaN)
// get zero forces and energies.
template <class T, class Law>
inline void tet_corner_forces(const T (&x)[4][3], const T (&v)[4][3], const T (&dm_inv)[9],
                              T volume0, const Law& law, T viscosity, bool any_viscous,
                              TetCornerForces<T>& out) {
  namespace sm = small_matrix;
  const T zero{};
  T Ds[9], F[9];
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 3; ++i) Ds[i + 3 * c] = x[c + 1][i] - x[0][i];
  sm::product(Ds, dm_inv, F);
  const T J = sm::determinant(F);
  out.jacobian = J;
  const auto valid = J > zero;  // false for NaN
  if constexpr (std::is_same_v<T, double>) {
    if (!valid) {
      for (auto& corner : out.force)
        for (auto& component : corner) component = zero;
      out.strain_energy = out.damping_power = zero;
      return;
    }
  }
  T P[9];
  out.strain_energy = law.stress_and_energy(F, J, P) * volume0;
  out.damping_power = zero;
  if (any_viscous) {
    T Dv[9], F_dot[9], F_inv_T[9], L[9], J_sigma[9], P_v[9];
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < 3; ++i) Dv[i + 3 * c] = v[c + 1][i] - v[0][i];
    sm::product(Dv, dm_inv, F_dot);
    sm::inverse_transposed(F, F_inv_T);
    sm::product_transposed(F_dot, F_inv_T, L);  // L = Ḟ·F⁻¹
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i)
        J_sigma[i + 3 * j] = J * (viscosity * (L[i + 3 * j] + L[j + 3 * i]));
    sm::product(J_sigma, F_inv_T, P_v);  // P_v = J·σ_v·F⁻ᵀ
    const auto viscous = viscosity > zero;
    for (int e = 0; e < 9; ++e) P[e] = select(viscous, P[e] + P_v[e], P[e]);
    out.damping_power = select(viscous, volume0 * sm::contraction(P_v, F_dot), zero);
  }
  // H = −V0·P·Dm⁻ᵀ: its columns are the forces on corners 1–3.
  T scaled[9], H[9];
  const T minus_volume = -volume0;
  for (int e = 0; e < 9; ++e) scaled[e] = minus_volume * P[e];
  sm::product_transposed(scaled, dm_inv, H);
  for (int i = 0; i < 3; ++i) {
    for (int c = 1; c < 4; ++c) out.force[c][i] = H[i + 3 * (c - 1)];
    out.force[0][i] = -((out.force[1][i] + out.force[2][i]) + out.force[3][i]);
  }
  if constexpr (!std::is_same_v<T, double>) {
    for (auto& corner : out.force)
      for (auto& component : corner) component = select(valid, component, zero);
    out.strain_energy = select(valid, out.strain_energy, zero);
    out.damping_power = select(valid, out.damping_power, zero);
  }
}

// Four tets of one elastic model, lane by lane: inputs filled by the caller.
struct TetLaneBatch {
  Lanes x[4][3], v[4][3];  // m, m/s (v read only when `any_viscous`)
  Lanes dm_inv[9];         // 1/m
  Lanes volume0;           // m³
  Lanes viscosity;         // Pa·s
  Lanes lambda, mu;        // Pa
  bool any_viscous = false;
  TetCornerForces<Lanes> out;
};

// tet_corner_forces on a batch, built for this CPU: AVX2 where the CPU has it, else the x86-64
// baseline; chosen when the program loads.  Both round every operation alike (no FMA).
void neo_hookean_tet_lanes(TetLaneBatch& batch);
void st_venant_kirchhoff_tet_lanes(TetLaneBatch& batch);

}  // namespace fdem
