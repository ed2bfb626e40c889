// Hyperelastic material laws as small value types with one interface:
//   first_piola(F) -> P (Pa),  energy_density(F) -> W (J/m^3 of reference volume),
//   stress_and_energy(F, J) -> both at once, sharing their work (J = det F, as F.determinant()
//   gives it): the element kernel's call; the two above are defined through it.
// Both are objective (depend on F only through C = FᵀF), so rigid rotations give zero stress.
#pragma once

#include <cmath>

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

// St. Venant–Kirchhoff: S = λ tr(E) I + 2μ E with the Green–St. Venant strain E = ½(FᵀF − I).
struct StVenantKirchhoff {
  LameParameters lame;

  // J is not used by this law.
  Mat3 first_piola(const Mat3& F) const { return stress_and_energy(F, 0.0).first_piola; }
  double energy_density(const Mat3& F) const { return stress_and_energy(F, 0.0).energy_density; }
  StressAndEnergy stress_and_energy(const Mat3& F, double /*J*/) const {
    const Mat3 E = 0.5 * (F.transpose() * F - Mat3::Identity());
    const double trE = E.trace();
    const Mat3 S = lame.lambda * trE * Mat3::Identity() + 2.0 * lame.mu * E;
    return {F * S, 0.5 * lame.lambda * trE * trE + lame.mu * E.squaredNorm()};
  }
};

// Compressible neo-Hookean: W = μ/2 (tr C − 3) − μ ln J + λ/2 (ln J)², P = μ(F − F⁻ᵀ) + λ ln J F⁻ᵀ.
// Valid for J > 0 only; the element kernel reports J ≤ 0 as an inverted element before calling it.
struct NeoHookean {
  LameParameters lame;

  Mat3 first_piola(const Mat3& F) const {
    return stress_and_energy(F, F.determinant()).first_piola;
  }
  double energy_density(const Mat3& F) const {
    return stress_and_energy(F, F.determinant()).energy_density;
  }
  // Stress and energy share one logarithm (the element kernel calls this, with its det F).
  StressAndEnergy stress_and_energy(const Mat3& F, double J) const {
    const double logJ = std::log(J);
    const Mat3 F_inv_T = F.inverse().transpose();
    return {
        lame.mu * (F - F_inv_T) + lame.lambda * logJ * F_inv_T,
        0.5 * lame.mu * (F.squaredNorm() - 3.0) - lame.mu * logJ + 0.5 * lame.lambda * logJ * logJ};
  }
};

enum class ElasticModel { neo_hookean, st_venant_kirchhoff };

}  // namespace fdem
