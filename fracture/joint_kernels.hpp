// Pure per-joint kernel: a 6-node cohesive joint between two coincident triangular faces.
//
// Node order: x[0..2] = a0, a1, a2 (face of element A), x[3..5] = b0, b1, b2 (face of element B),
// b_i coincident with a_i at t = 0, and (a1 − a0) × (a2 − a0) pointing out of A, into B.
// Integration: nodal (3-point Newton–Cotes) rule, point i = the gap Δ_i = b_i − a_i, weight A0/3.
// Nodal rules keep cohesive interfaces free of the traction oscillations Gauss rules show.
//
// Frame: the current mid-surface through m_i = (a_i + b_i)/2: n ∥ (m1 − m0) × (m2 − m0),
// t1 ∥ m1 − m0, t2 = n × t1.  The local opening d_i = (Δ_i·t1, Δ_i·t2, Δ_i·n) is invariant under
// rigid motion.  Forces are the exact gradient of the stored energy ψ(x) = Σ (A0/3)·φ(d_i)
// including the rotation of the frame with the nodes, so Σf = 0 and Σx×f = 0 hold to round-off
// for any deformation.
#pragma once

#include <cstdint>

#include "core/types.hpp"
#include "fracture/cohesive_law.hpp"

namespace fdem {

enum class FailureMode : std::uint8_t {
  none,           // not broken
  tension,        // opening did ≥ 99 % of the damage (by o² share of D²)
  shear,          // slip did ≥ 99 %
  mixed_tension,  // both, opening dominated
  mixed_shear,    // both, slip dominated
};

inline const char* failure_mode_name(FailureMode m) {
  switch (m) {
    case FailureMode::tension:
      return "tension";
    case FailureMode::shear:
      return "shear";
    case FailureMode::mixed_tension:
      return "mixed (tension dominated)";
    case FailureMode::mixed_shear:
      return "mixed (shear dominated)";
    default:
      return "none";
  }
}

struct JointHistory {
  CohesivePointState point[3];
  bool broken = false;
  FailureMode mode = FailureMode::none;
  double failure_time = -1.0;  // s; the caller sets it when a step reports newly_broken

  // Joint damage for output fields: mean of the three points (the rule weights them equally).
  double damage() const { return (point[0].damage + point[1].damage + point[2].damage) / 3.0; }
};

struct JointForce {
  Vec3 force[6];                 // force of the joint on a0, a1, a2, b0, b1, b2 (N)
  double stored_energy = 0.0;    // elastic energy held by the joint now (J)
  double fracture_energy = 0.0;  // dissipated by bond degradation during this update (J)
  double friction_energy = 0.0;  // dissipated by Coulomb slip during this update (J)
  bool newly_broken = false;     // every point reached D = 1 in this update
  bool degenerate = false;       // mid-surface has no area: forces not computed
};

// Share of the damage due to opening → failure mode (called once, when the joint breaks).
inline FailureMode classify_failure(const JointHistory& h, const CohesiveLaw& law) {
  double opening = 0.0, slip = 0.0;
  for (const auto& p : h.point) {
    opening += p.max_opening_ratio * p.max_opening_ratio;
    const double s = law.critical_slip() > 0.0 ? p.slip_length / law.critical_slip() : 0.0;
    slip += s * s;
  }
  const double share = opening / std::max(opening + slip, 1e-300);
  if (share >= 0.99) return FailureMode::tension;
  if (share <= 0.01) return FailureMode::shear;
  return share >= 0.5 ? FailureMode::mixed_tension : FailureMode::mixed_shear;
}

// What a pristine joint (no point ever past its peak opening or slipping) keeps between steps:
// the opening and shear of its three points at the last update, for the energy increments of the
// update in which it first damages or slips.  The rest of its JointHistory is zero.
struct IntactJointState {
  double previous_opening[3] = {0.0, 0.0, 0.0};   // m
  double previous_shear_sq[3] = {0.0, 0.0, 0.0};  // Pa²
};

inline bool pristine(const JointHistory& h) {
  for (const auto& p : h.point)
    if (p.max_opening_ratio != 0.0 || p.slip_length != 0.0) return false;
  return true;
}

// The current mid-surface of a joint: m_i = (a_i + b_i)/2, e = m1 − m0, g = m2 − m0, unit normal
// n ∥ e × g.  False when it has no area.
struct JointFrame {
  Vec3 e, g, n;
  double n_len = 0.0, inv_n_len = 0.0;
};
inline bool joint_frame(const Vec3 (&x)[6], JointFrame& frame) {
  const Vec3 m0 = 0.5 * (x[0] + x[3]);
  frame.e = 0.5 * (x[1] + x[4]) - m0;
  frame.g = 0.5 * (x[2] + x[5]) - m0;
  const Vec3 normal_raw = frame.e.cross(frame.g);
  frame.n_len = normal_raw.norm();
  if (!(frame.n_len > 0.0)) return false;
  frame.inv_n_len = 1.0 / frame.n_len;
  frame.n = normal_raw * frame.inv_n_len;
  return true;
}

// The three points' gap Δ = b_i − a_i (m), opening Δ·n (m) and shear stress squared
// max(0, k_t²(|Δ|² − (Δ·n)²)) (Pa²) in the frame's normal n: what the intact step tests against
// the strength and what it leaves in the state.
inline void intact_point_measures(const Vec3 (&x)[6], const Vec3& n, double k_t, Vec3 (&gap)[3],
                                  double (&dn)[3], double (&shear_sq)[3]) {
  for (int i = 0; i < 3; ++i) {
    gap[i] = x[3 + i] - x[i];
    dn[i] = gap[i].dot(n);
    shear_sq[i] = std::max(0.0, k_t * k_t * (gap[i].squaredNorm() - dn[i] * dn[i]));
  }
}

// What a pristine joint's step leaves in its state at positions x (m), by the step's own
// measures: the joint stage keeps no state for pristine joints and, when one first leaves the
// pristine state, rebuilds the previous step's from the previous positions.  False (state
// zeroed) when the mid-surface has no area.
inline bool intact_state_at(const Vec3 (&x)[6], const CohesiveLaw& law, IntactJointState& state) {
  state = IntactJointState{};
  JointFrame frame;
  if (!joint_frame(x, frame)) return false;
  Vec3 gap[3];
  double dn[3];
  intact_point_measures(x, frame.n, law.tangential_stiffness(), gap, dn, state.previous_shear_sq);
  for (int i = 0; i < 3; ++i) state.previous_opening[i] = std::max(dn[i], 0.0);
  return true;
}

// Fast path of joint_force for a pristine joint whose points stay below strength:
// φ = ½k_t|Δ|² + ½(k_n − k_t)(Δ·n)², which depends on the frame only through n, so t1, t2 are not
// needed.  Returns false (and changes nothing) when a point reaches its strength.
inline bool joint_intact_step(const Vec3 (&x)[6], const JointFrame& frame, double w,
                              const CohesiveLaw& law, IntactJointState& state, JointForce& out) {
  const Vec3& n = frame.n;
  const double k_n = law.normal_stiffness(), k_t = law.tangential_stiffness();
  const double peak = law.peak_opening(), cohesion = law.cohesion();
  const double friction = k_n * law.tan_friction();  // σc·tanφ = −dn·k_n·tanφ
  Vec3 gap[3];
  double dn[3], shear_sq[3];
  intact_point_measures(x, n, k_t, gap, dn, shear_sq);
  for (int i = 0; i < 3; ++i) {
    const double strength = cohesion - friction * std::min(dn[i], 0.0);
    if (dn[i] > peak || shear_sq[i] > strength * strength) return false;
  }
  Vec3 v = Vec3::Zero();  // Σ w(k_n − k_t)(Δ·n)·(I − nnᵀ)Δ: the energy's pull on n
  for (int i = 0; i < 3; ++i) {
    const Vec3 traction = k_t * gap[i] + (k_n - k_t) * dn[i] * n;
    out.force[i] += w * traction;
    out.force[3 + i] -= w * traction;
    v += (w * (k_n - k_t) * dn[i]) * (gap[i] - dn[i] * n);
    out.stored_energy += w * (0.5 * k_n * dn[i] * dn[i] + 0.5 * shear_sq[i] / k_t);
    state.previous_opening[i] = std::max(dn[i], 0.0);
    state.previous_shear_sq[i] = shear_sq[i];
  }
  // δψ = v·δn = v·δN/|N| with δN = δe × g + e × δg.
  const Vec3 grad_e = frame.g.cross(v) * frame.inv_n_len,
             grad_g = v.cross(frame.e) * frame.inv_n_len;
  const Vec3 grad_m[3] = {-grad_e - grad_g, grad_e, grad_g};
  for (int i = 0; i < 3; ++i) {
    out.force[i] -= 0.5 * grad_m[i];
    out.force[3 + i] -= 0.5 * grad_m[i];
  }
  return true;
}

// Advances one joint to positions x (m) and returns its nodal forces and energies.  area0 is the
// face area at t = 0 (m²).  A broken joint exerts no force (its faces are handed to contact).
// Pure: history in, history out; no allocation.
inline JointForce joint_force(const Vec3 (&x)[6], double area0, const CohesiveLaw& law,
                              JointHistory& history) {
  JointForce out;
  for (auto& f : out.force) f.setZero();
  if (history.broken) return out;

  JointFrame frame;
  if (!joint_frame(x, frame)) {
    out.degenerate = true;
    return out;
  }
  const double w = area0 / 3.0;
  if (pristine(history)) {
    IntactJointState state;
    if (joint_intact_step(x, frame, w, law, state, out)) {
      for (int i = 0; i < 3; ++i) {
        history.point[i].previous_opening = state.previous_opening[i];
        history.point[i].previous_shear_sq = state.previous_shear_sq[i];
      }
      return out;
    }
  }
  const Vec3 &e = frame.e, &g = frame.g, &n = frame.n;
  const double n_len = frame.n_len;

  const double e_len = e.norm();
  const Vec3 t1 = e / e_len;
  const Vec3 t2 = n.cross(t1);
  Vec3 moment = Vec3::Zero();  // M = Σ w·τ_i × Δ_i: couples the tractions to the frame rotation
  int failed_points = 0;
  for (int i = 0; i < 3; ++i) {
    const Vec3 gap = x[3 + i] - x[i];
    const Vec3 d(gap.dot(t1), gap.dot(t2), gap.dot(n));
    const CohesivePointResult r = law.update(d, history.point[i]);
    const Vec3 traction = r.traction[0] * t1 + r.traction[1] * t2 + r.traction[2] * n;
    out.force[i] += w * traction;
    out.force[3 + i] -= w * traction;
    moment += w * traction.cross(gap);
    out.stored_energy += w * r.stored_energy;
    out.fracture_energy += w * r.fracture_energy;
    out.friction_energy += w * r.friction_energy;
    if (history.point[i].damage >= 1.0) ++failed_points;
  }

  // Frame terms: δψ = M·δω with δω the frame's rotation; with g1 = g·t1, g2 = g·t2 = |N|/|e|:
  // ∂ψ/∂e = (M_n t2 − M_2 n)/|e| − M_1·g1/(|e|·g2)·n,  ∂ψ/∂g = M_1/g2·n.
  const double m_n = moment.dot(n), m_1 = moment.dot(t1), m_2 = moment.dot(t2);
  const double g1 = g.dot(t1), g2 = n_len / e_len;
  const Vec3 grad_e = (m_n * t2 - m_2 * n - (m_1 * g1 / g2) * n) / e_len;
  const Vec3 grad_g = (m_1 / g2) * n;
  const Vec3 grad_m[3] = {-grad_e - grad_g, grad_e, grad_g};
  for (int i = 0; i < 3; ++i) {  // m_i = (a_i + b_i)/2: each node takes half
    out.force[i] -= 0.5 * grad_m[i];
    out.force[3 + i] -= 0.5 * grad_m[i];
  }

  if (failed_points == 3) {
    history.broken = true;
    history.mode = classify_failure(history, law);
    out.newly_broken = true;
  }
  return out;
}

}  // namespace fdem
