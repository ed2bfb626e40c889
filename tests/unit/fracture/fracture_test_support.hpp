// Shared fixtures for the fracture unit tests: a rock-like joint law and drivers that push one
// integration point (or one joint) along a prescribed path and add up the energies.
#pragma once

#include <cmath>
#include <functional>

#include "fracture/cohesive_law.hpp"
#include "fracture/joint_kernels.hpp"

namespace fdem::test {

// f_t = 5 MPa, c = 10 MPa, φ = 30°, G_I = 50 J/m², G_II = 250 J/m², p = 3e11 Pa (10·E for
// E = 30 GPa), h = 0.1 m → k = 3e12 Pa/m, δt = 1.67 µm, δc = 25.4 µm, s_c = 64.7 µm.
inline CohesiveParameters rock_parameters() {
  CohesiveParameters p;
  p.tensile_strength = 5.0e6;
  p.cohesion = 10.0e6;
  p.friction_angle_deg = 30.0;
  p.energy_I = 50.0;
  p.energy_II = 250.0;
  p.normal_penalty = 3.0e11;
  p.tangential_penalty = 3.0e11;
  p.element_size = 0.1;
  return p;
}

// Independent copy of eq. 20 (not the library's), for reference integrals.
inline double z_reference(double D, double a = 0.63, double b = 1.8, double c = 6.0) {
  if (D >= 1.0) return 0.0;
  return (1.0 - (a + b - 1.0) / (a + b) * std::exp(D * (a + c * b) / ((a + b) * (1.0 - a - b)))) *
         (a * (1.0 - D) + b * std::pow(1.0 - D, c));
}

// Composite Simpson on [lo, hi] with n (even) intervals.
inline double simpson(const std::function<double(double)>& f, double lo, double hi, int n) {
  const double h = (hi - lo) / n;
  double s = f(lo) + f(hi);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4.0 : 2.0) * f(lo + i * h);
  return s * h / 3.0;
}

// Totals of a point driven along d(s), s = 0..1 in `steps` increments.
struct PathTotals {
  double work = 0.0;                            // trapezoid ∫T·dd (J/m²)
  double fracture = 0.0;                        // Σ fracture increments (J/m²)
  double friction = 0.0;                        // Σ friction increments (J/m²)
  double stored_end = 0.0;                      // stored energy at the end (J/m²)
  double max_normal = -1e300, max_shear = 0.0;  // peak σ and |τ| (Pa)
};

inline PathTotals drive_point(const CohesiveLaw& law, CohesivePointState& st,
                              const std::function<Vec3(double)>& path, int steps,
                              PathTotals totals = {}) {
  Vec3 d_old = path(0.0);
  CohesivePointResult r_old = law.update(d_old, st);
  for (int k = 1; k <= steps; ++k) {
    const Vec3 d = path(static_cast<double>(k) / steps);
    const CohesivePointResult r = law.update(d, st);
    totals.work += 0.5 * (r.traction + r_old.traction).dot(d - d_old);
    totals.fracture += r.fracture_energy;
    totals.friction += r.friction_energy;
    totals.max_normal = std::max(totals.max_normal, r.traction[2]);
    totals.max_shear = std::max(totals.max_shear, std::hypot(r.traction[0], r.traction[1]));
    totals.stored_end = r.stored_energy;
    d_old = d;
    r_old = r;
  }
  return totals;
}

}  // namespace fdem::test
