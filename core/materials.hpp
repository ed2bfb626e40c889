// Hyperelastic material laws as small value types with one interface:
//   first_piola(F) -> P (Pa),  energy_density(F) -> W (J/m^3 of reference volume),
//   stress_and_energy(F, J) -> both at once, sharing their work (J = det F, as F.determinant()
//   gives it): the element kernel's call; the two above are defined through it.
// Both are objective (depend on F only through C = FᵀF), so rigid rotations give zero stress.
#pragma once

#include <cmath>

#include "core/small_matrix.hpp"
#include "core/types.hpp"

namespace fdem {

// Lamé parameters from Young's modulus E (Pa) and Poisson's ratio ν.
struct LameParameters {
  double lambda = 0.0;  // Pa
  double mu = 0.0;      // Pa
  static LameParameters from_young_poisson(double young, double poisson) {
    return {young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson)),
            young / (2.0 * (1.0 + poisson))};
  }
  // P-wave (constrained) modulus M = λ + 2μ: sets the dilatational wave speed √(M/ρ).
  double p_wave_modulus() const { return lambda + 2.0 * mu; }
};

struct StressAndEnergy {
  Mat3 first_piola;       // P (Pa)
  double energy_density;  // W (J/m^3)
};

// The laws' arithmetic on F as nine values (column-major), for one element (T = double) or four
// side by side (T = Lanes): P into `P` (Pa), W returned (J/m^3).  The element kernel's call; the
// Mat3 interfaces below are defined through them, so there is one formula per law.
template <class T>
struct StVenantKirchhoffLaw {
  T lambda, mu;  // Pa
  T stress_and_energy(const T (&F)[9], T /*J*/, T (&P)[9]) const {
    T C[9], E[9], S[9];
    small_matrix::transposed_product(F, F, C);
    for (int e = 0; e < 9; ++e) E[e] = 0.5 * (C[e] - identity(e));
    const T trace = E[0] + (E[4] + E[8]);  // the order of Eigen's trace
    const T lambda_trace = lambda * trace, two_mu = 2.0 * mu;
    for (int e = 0; e < 9; ++e) S[e] = lambda_trace * identity(e) + two_mu * E[e];
    small_matrix::product(F, S, P);
    return ((0.5 * lambda) * trace) * trace + mu * small_matrix::contraction(E, E);
  }
  static double identity(int e) { return e % 4 == 0 ? 1.0 : 0.0; }
};

template <class T>
struct NeoHookeanLaw {
  T lambda, mu;  // Pa
  // Valid for J > 0 only (the element kernel reports J ≤ 0 as an inverted element).
  T stress_and_energy(const T (&F)[9], T J, T (&P)[9]) const {
    const T log_j = log_of(J);  // stress and energy share it
    T F_inv_T[9];
    small_matrix::inverse_transposed(F, F_inv_T);
    const T lambda_log_j = lambda * log_j;
    for (int e = 0; e < 9; ++e) P[e] = mu * (F[e] - F_inv_T[e]) + lambda_log_j * F_inv_T[e];
    return ((0.5 * mu) * (small_matrix::contraction(F, F) - 3.0) - mu * log_j) +
           ((0.5 * lambda) * log_j) * log_j;
  }
};

// A law's Mat3 interface over its nine-value arithmetic.
template <template <class> class Law>
inline StressAndEnergy stress_and_energy_of(LameParameters lame, const Mat3& F, double J) {
  double f[9], p[9];
  for (int e = 0; e < 9; ++e) f[e] = F.data()[e];
  StressAndEnergy out;
  out.energy_density = Law<double>{lame.lambda, lame.mu}.stress_and_energy(f, J, p);
  out.first_piola = Eigen::Map<const Mat3>(p);
  return out;
}

// St. Venant–Kirchhoff: S = λ tr(E) I + 2μ E with the Green–St. Venant strain E = ½(FᵀF − I).
struct StVenantKirchhoff {
  LameParameters lame;
  template <class T>
  using Law = StVenantKirchhoffLaw<T>;

  // J is not used by this law.
  Mat3 first_piola(const Mat3& F) const { return stress_and_energy(F, 0.0).first_piola; }
  double energy_density(const Mat3& F) const { return stress_and_energy(F, 0.0).energy_density; }
  StressAndEnergy stress_and_energy(const Mat3& F, double J) const {
    return stress_and_energy_of<StVenantKirchhoffLaw>(lame, F, J);
  }
};

// Compressible neo-Hookean: W = μ/2 (tr C − 3) − μ ln J + λ/2 (ln J)², P = μ(F − F⁻ᵀ) + λ ln J F⁻ᵀ.
// Valid for J > 0 only; the element kernel reports J ≤ 0 as an inverted element before calling it.
struct NeoHookean {
  LameParameters lame;
  template <class T>
  using Law = NeoHookeanLaw<T>;

  Mat3 first_piola(const Mat3& F) const {
    return stress_and_energy(F, F.determinant()).first_piola;
  }
  double energy_density(const Mat3& F) const {
    return stress_and_energy(F, F.determinant()).energy_density;
  }
  // Stress and energy share one logarithm (J = det F).
  StressAndEnergy stress_and_energy(const Mat3& F, double J) const {
    return stress_and_energy_of<NeoHookeanLaw>(lame, F, J);
  }
};

enum class ElasticModel { neo_hookean, st_venant_kirchhoff };

}  // namespace fdem
