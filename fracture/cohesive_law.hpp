// Cohesive law of the joint elements: the combined single and smeared crack model (Munjiza,
// Andrews & White 1999) with a linear penalty pre-peak branch, the softening curve z(D) of eq. 20,
// energy-calibrated critical openings, Mohr–Coulomb shear strength with non-softening friction,
// and irreversible damage.  docs/fracture-model.md gives the equations and the reasoning.
//
// Local coordinates of one integration point: opening d = (s1, s2, n): s1, s2 sliding along the
// joint's in-plane axes t1, t2 (m), n normal opening (m, > 0 opens, < 0 interpenetrates).
// Tractions T = (τ1, τ2, σ) in Pa follow the same order; σ > 0 is tension.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/types.hpp"

namespace fdem {

// z(D) = [1 − (a+b−1)/(a+b)·exp(D·(a+c·b)/((a+b)(1−a−b)))]·[a(1−D) + b(1−D)^c]   (eq. 20)
class SofteningCurve {
 public:
  // Validates (a, b, c) — z must fall monotonically from 1 to 0 — and integrates ∫₀¹ z dD once.
  // Throws InputError when the curve is not a softening curve.
  SofteningCurve(double a = 0.63, double b = 1.8, double c = 6.0);

  double a() const { return a_; }
  double b() const { return b_; }
  double c() const { return c_; }
  double integral() const { return integral_; }    // ∫₀¹ z(D) dD (0.3863 for the defaults)
  double max_slope() const { return max_slope_; }  // max over [0,1] of −dz/dD

  double z(double D) const {
    if (D <= 0.0) return 1.0;
    if (D >= 1.0) return 0.0;
    const double one_minus = 1.0 - D;
    return (1.0 - amp_ * std::exp(rate_ * D)) * (a_ * one_minus + b_ * std::pow(one_minus, c_));
  }
  double dz(double D) const {
    if (D < 0.0 || D > 1.0) return 0.0;
    const double one_minus = 1.0 - D;
    const double e = amp_ * std::exp(rate_ * D);
    const double poly = a_ * one_minus + b_ * std::pow(one_minus, c_);
    const double dpoly = -a_ - b_ * c_ * std::pow(one_minus, c_ - 1.0);
    return -rate_ * e * poly + (1.0 - e) * dpoly;
  }

 private:
  double a_, b_, c_;
  double amp_;   // (a+b−1)/(a+b)
  double rate_;  // (a+c·b)/((a+b)(1−a−b))
  double integral_ = 0.0, max_slope_ = 0.0;
};

// User-level inputs (SI units).  Field names follow the scene's `fracture:` block.
struct CohesiveParameters {
  double tensile_strength = 0.0;  // f_t (Pa), > 0
  double cohesion = 0.0;          // c (Pa), ≥ 0; 0 makes a dry (purely frictional) shear response
  double friction_angle_deg = 0.0;  // φ (degrees), in [0, 90)
  double energy_I = 0.0;            // G_I (J/m²), mode I fracture energy
  double energy_II = 0.0;           // G_II (J/m²), mode II fracture energy (unused when c = 0)
  double normal_penalty = 0.0;      // p_n (Pa): normal stiffness is p_n/h
  double tangential_penalty = 0.0;  // p_t (Pa): tangential stiffness is p_t/h
  double element_size = 0.0;        // h (m): representative size of the elements the joints bind
  double softening_a = 0.63, softening_b = 1.8, softening_c = 6.0;
};

// History of one integration point.  Every field is irreversible or bookkeeping for the energy
// accounting; a fresh joint is all zeros.
struct CohesivePointState {
  double max_opening_ratio = 0.0;       // o_max = max ⟨δn − δt⟩/(δc − δt) seen so far
  double slip_length = 0.0;             // κ: accumulated plastic slip path length (m)
  double plastic_slip[2] = {0.0, 0.0};  // s_p in the local (t1, t2) axes (m)
  double damage = 0.0;                  // D = min(1, √(o_max² + (κ/s_c)²))
  double previous_opening = 0.0;        // ⟨δn⟩₊ at the previous update (m), for the energy
  double previous_shear_sq = 0.0;       // |τ|² at the previous update (Pa²), for the energy
};

// What one point update returns (per unit reference area).
struct CohesivePointResult {
  Vec3 traction;               // (τ1, τ2, σ) in Pa; the bond pulls face B back with −traction
  double stored_energy = 0.0;  // J/m²: ½S(D)k_n⟨δn⟩₊² + ½k_n⟨δn⟩₋² + ½|τ|²/k_t
  double fracture_energy = 0.0;  // J/m² dissipated this update by bond degradation
  double friction_energy = 0.0;  // J/m² dissipated this update by Coulomb friction
  bool elastic = true;           // no damage growth and no slip this update
};

// The smallest penalties (Pa) a parameter set works with (the law needs strictly more):
// normal: the pre-peak energy ½·f_t²·h/p_n must stay below G_I → f_t²·h/(2·G_I);
// tangential: the cohesion's softening over the slip must not be steeper than the elastic slope
// p_t/h (snap-back) → I·max|z′|·c²·h/G_II (0 for a dry joint, c = 0).
struct PenaltyBounds {
  double normal = 0.0, tangential = 0.0;
};
PenaltyBounds minimum_penalties(const CohesiveParameters& p, const SofteningCurve& curve);

class CohesiveLaw {
 public:
  explicit CohesiveLaw(const CohesiveParameters& p);  // validates; throws InputError
  // The same with the softening curve of p already built (many laws share one curve; building it
  // samples z 20 001 times).
  CohesiveLaw(const CohesiveParameters& p, const SofteningCurve& curve);

  const CohesiveParameters& parameters() const { return params_; }
  const SofteningCurve& softening() const { return curve_; }
  double tensile_strength() const { return params_.tensile_strength; }
  double cohesion() const { return params_.cohesion; }
  double tan_friction() const { return tan_phi_; }
  double normal_stiffness() const { return k_n_; }      // p_n/h (Pa/m)
  double tangential_stiffness() const { return k_t_; }  // p_t/h (Pa/m)
  double peak_opening() const { return delta_t_; }      // δt = f_t·h/p_n (m)
  double critical_opening() const { return delta_c_; }  // δc: σ reaches 0 (m)
  double critical_slip() const { return slip_c_; }      // s_c = G_II/(I·c): κ at which D = 1 (m)
  // Sliding at the shear peak under compressive normal stress σc ≥ 0: τ_max·h/p_t (m).
  double peak_slip(double compression) const { return shear_strength(compression) / k_t_; }
  // Mohr–Coulomb peak shear strength τ_max = c + σc·tanφ of an intact joint (Pa).
  double shear_strength(double compression) const {
    return params_.cohesion + std::max(compression, 0.0) * tan_phi_;
  }
  // Secant factor of the normal bond: σ = S(D)·k_n·δn on the tension side.
  double secant_factor(double D) const {
    if (D <= 0.0) return 1.0;
    if (D >= 1.0) return 0.0;
    return curve_.z(D) * delta_t_ / (delta_t_ + D * (delta_c_ - delta_t_));
  }
  double damage_of(double opening_ratio, double slip_length) const {
    const double s = slip_length * inv_slip_c_;
    const double D = std::sqrt(opening_ratio * opening_ratio + s * s);
    return D >= 1.0 - 1e-12 ? 1.0 : D;  // snap the last round-off so that failure is exact
  }

  // Advances one integration point to the local opening d = (s1, s2, n) and returns tractions,
  // energies and the updated history.  Pure; no allocation.
  inline CohesivePointResult update(const Vec3& d, CohesivePointState& state) const;

 private:
  // Plastic slip increment x ∈ [x_lo, x_hi] solving k_t(E − x) = c·z(D(κ+x)) + σc·tanφ.
  double solve_slip(double trial, double x_lo, double opening_ratio, double kappa,
                    double friction_stress) const;

  CohesiveParameters params_;
  SofteningCurve curve_;
  double tan_phi_ = 0.0, k_n_ = 0.0, k_t_ = 0.0;
  double delta_t_ = 0.0, delta_c_ = 0.0, inv_opening_range_ = 0.0;
  double slip_c_ = 0.0, inv_slip_c_ = 0.0;
};

inline CohesivePointResult CohesiveLaw::update(const Vec3& d, CohesivePointState& st) const {
  CohesivePointResult r;
  const double dn = d[2];
  const double opening = std::max(dn, 0.0);
  const double compression = std::max(-k_n_ * dn, 0.0);  // σc ≥ 0 (Pa)
  const double damage_old = st.damage;

  // Mode I history: the largest normalised post-peak opening ever reached.
  if (dn > delta_t_) {
    st.max_opening_ratio =
        std::max(st.max_opening_ratio, std::min(1.0, (dn - delta_t_) * inv_opening_range_));
  }
  // Intact points (the common case) skip the square root.
  double damage = st.max_opening_ratio == 0.0 && st.slip_length == 0.0
                      ? 0.0
                      : damage_of(st.max_opening_ratio, st.slip_length);

  // Shear: elastic trial from the plastic slip, Coulomb-type yield c·z(D) + σc·tanφ.
  const double friction_stress = compression * tan_phi_;
  const double e1 = d[0] - st.plastic_slip[0], e2 = d[1] - st.plastic_slip[1];
  const double trial_sq = e1 * e1 + e2 * e2;
  const double yield = params_.cohesion * curve_.z(damage) + friction_stress;
  double slip_increment = 0.0, fracture = 0.0, friction = 0.0;
  double shear_sq = k_t_ * k_t_ * trial_sq;  // |τ|²
  if (shear_sq <= yield * yield) {
    r.traction[0] = k_t_ * e1;
    r.traction[1] = k_t_ * e2;
  } else {
    const double trial = std::sqrt(trial_sq);
    slip_increment = solve_slip(trial, std::max(0.0, trial - yield / k_t_), st.max_opening_ratio,
                                st.slip_length, friction_stress);
    st.slip_length += slip_increment;
    damage = damage_of(st.max_opening_ratio, st.slip_length);
    const double ratio = slip_increment / trial;
    st.plastic_slip[0] += ratio * e1;
    st.plastic_slip[1] += ratio * e2;
    const double scale = k_t_ * (1.0 - ratio);  // |τ| = k_t(E − Δκ) = yield
    r.traction[0] = scale * e1;
    r.traction[1] = scale * e2;
    const double shear = k_t_ * (trial - slip_increment);
    shear_sq = shear * shear;
    // Trapezoid of |τ| over the slip; the friction share σc·tanφ·Δκ never softens, the rest is
    // the work of the degrading cohesive bond.
    const double plastic_work = 0.5 * (std::sqrt(st.previous_shear_sq) + shear) * slip_increment;
    friction = params_.cohesion > 0.0 ? std::min(plastic_work, friction_stress * slip_increment)
                                      : plastic_work;
    fracture = plastic_work - friction;
  }

  // Normal: full penalty in compression (closed cracks carry load), secant branch in tension.
  const double secant_new = secant_factor(damage);
  r.traction[2] = dn > 0.0 ? secant_new * k_n_ * dn : k_n_ * dn;

  // Energy: stored potential, and dissipation increments that make trapezoidal work exact.
  r.stored_energy = 0.5 * (dn > 0.0 ? secant_new : 1.0) * k_n_ * dn * dn + 0.5 * shear_sq / k_t_;
  if (damage > damage_old) {
    fracture +=
        0.5 * k_n_ * st.previous_opening * opening * (secant_factor(damage_old) - secant_new);
  }
  r.fracture_energy = fracture;
  r.friction_energy = friction;
  r.elastic = slip_increment == 0.0 && damage == damage_old;
  st.damage = damage;
  st.previous_opening = opening;
  st.previous_shear_sq = shear_sq;
  return r;
}

}  // namespace fdem
