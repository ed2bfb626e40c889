// The pristine joint's step for a batch of joints at once: the hot loop of an intact jointed body.
//
// Same arithmetic, operation for operation, as joint_frame + joint_intact_step
// (fracture/joint_kernels.hpp), so forces and energies are bit-identical to it (tested).  It
// leaves no state: the joint stage rebuilds a joint's last pristine state only when the joint
// leaves that state (intact_state_at).
// Four joints go side by side in vector lanes, without branches, so that one instruction computes
// all four: the reference version works on one joint's Eigen 3-vectors, which leave most of a
// vector register empty and stall on packed stores reloaded as scalars.  The reference stays the
// one joint_force uses and the one the tests compare with.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "core/lanes.hpp"
#include "fracture/cohesive_law.hpp"
#include "fracture/joint_kernels.hpp"

namespace fdem {

// What the intact step reads of a CohesiveLaw, gathered once per law.
struct IntactJointLaw {
  double k_n = 0.0;       // normal stiffness (Pa/m)
  double k_t = 0.0;       // tangential stiffness (Pa/m)
  double peak = 0.0;      // opening at the tensile strength (m)
  double cohesion = 0.0;  // Pa
  double friction = 0.0;  // k_n·tanφ: σc·tanφ = −dn·k_n·tanφ (Pa/m)

  IntactJointLaw() = default;
  explicit IntactJointLaw(const CohesiveLaw& law)
      : k_n(law.normal_stiffness()),
        k_t(law.tangential_stiffness()),
        peak(law.peak_opening()),
        cohesion(law.cohesion()),
        friction(law.normal_stiffness() * law.tan_friction()) {}
};

enum class IntactStep : unsigned char {
  done,        // forces and energy written
  degenerate,  // the mid-surface has no area: no force (as joint_force reports it)
  leaves,      // a point reached its strength: nothing to use, the full law takes over
};

// Four joints side by side (core/lanes.hpp): one instruction for all four on AVX2, two on the
// x86-64 baseline (SSE2); every lane rounds exactly as a scalar operation would.
constexpr int intact_lanes = lane_count;

// One batch: the caller fills the inputs of every lane (set_lanes; an unused lane with any valid
// joint, e.g. lane 0's) and reads the outputs of the lanes whose step is not `leaves`.
struct IntactJointBatch {
  // Inputs.
  Lanes x[18];                               // a0, a1, a2, b0, b1, b2 (m), coordinate by coordinate
  Lanes w;                                   // A0/3 (m²)
  Lanes k_n, k_t, peak, cohesion, friction;  // the joint's law
  // Outputs.
  IntactStep step[intact_lanes];
  Lanes force[18];      // on a0 … b2 (N); 0 when degenerate
  Lanes stored_energy;  // J; 0 when degenerate
};

// The batch's inputs: lane l is the joint whose six nodes are node_x[3·id[l][0…5]] (m), with
// w[l] = A0/3 (m²) and *law[l].  Each input vector is built in registers from its four values and
// stored once (four scalar stores read back as one vector would stall the kernel's loads).
inline void set_lanes(IntactJointBatch& b, const double* node_x,
                      const LocalIndex* const (&id)[intact_lanes], const double (&w)[intact_lanes],
                      const IntactJointLaw* const (&law)[intact_lanes]) {
  static_assert(intact_lanes == 4, "the initialisers below name four lanes");
  for (int i = 0; i < 6; ++i) {
    const double* p[intact_lanes];
    for (int l = 0; l < intact_lanes; ++l) p[l] = node_x + 3 * static_cast<std::size_t>(id[l][i]);
    for (int k = 0; k < 3; ++k) b.x[3 * i + k] = Lanes{p[0][k], p[1][k], p[2][k], p[3][k]};
  }
  b.w = Lanes{w[0], w[1], w[2], w[3]};
  if (law[0] == law[1] && law[0] == law[2] && law[0] == law[3]) {  // one law: broadcast it
    const IntactJointLaw& one = *law[0];
    const Lanes zero = {0.0, 0.0, 0.0, 0.0};
    b.k_n = zero + one.k_n;
    b.k_t = zero + one.k_t;
    b.peak = zero + one.peak;
    b.cohesion = zero + one.cohesion;
    b.friction = zero + one.friction;
    return;
  }
  b.k_n = Lanes{law[0]->k_n, law[1]->k_n, law[2]->k_n, law[3]->k_n};
  b.k_t = Lanes{law[0]->k_t, law[1]->k_t, law[2]->k_t, law[3]->k_t};
  b.peak = Lanes{law[0]->peak, law[1]->peak, law[2]->peak, law[3]->peak};
  b.cohesion = Lanes{law[0]->cohesion, law[1]->cohesion, law[2]->cohesion, law[3]->cohesion};
  b.friction = Lanes{law[0]->friction, law[1]->friction, law[2]->friction, law[3]->friction};
}

inline void intact_joint_steps(IntactJointBatch& b) {
  const Lanes zero = {0.0, 0.0, 0.0, 0.0}, half = zero + 0.5, one = zero + 1.0;
  // Mid-surface frame: m_i = (a_i + b_i)/2, e = m1 − m0, g = m2 − m0, n ∥ e × g.
  Lanes e[3], g[3];
  for (int k = 0; k < 3; ++k) {
    const Lanes m0 = half * (b.x[k] + b.x[9 + k]);
    e[k] = half * (b.x[3 + k] + b.x[12 + k]) - m0;
    g[k] = half * (b.x[6 + k] + b.x[15 + k]) - m0;
  }
  const Lanes raw[3] = {e[1] * g[2] - e[2] * g[1], e[2] * g[0] - e[0] * g[2],
                        e[0] * g[1] - e[1] * g[0]};
  const Lanes n_len_sq = raw[0] * raw[0] + raw[1] * raw[1] + raw[2] * raw[2];
  Lanes n_len = zero;
  for (int l = 0; l < intact_lanes; ++l) n_len[l] = std::sqrt(n_len_sq[l]);
  const LaneMask flat = !(n_len > zero);
  const Lanes inv_n_len = one / (flat ? one : n_len);
  const Lanes n[3] = {raw[0] * inv_n_len, raw[1] * inv_n_len, raw[2] * inv_n_len};

  // Gap, opening and shear of each point; a point at its strength ends the intact state.
  Lanes gap[3][3], dn[3], shear_sq[3];
  LaneMask weak = flat & 0;
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) gap[i][k] = b.x[9 + 3 * i + k] - b.x[3 * i + k];
    dn[i] = gap[i][0] * n[0] + gap[i][1] * n[1] + gap[i][2] * n[2];
    const Lanes gap_sq = gap[i][0] * gap[i][0] + gap[i][1] * gap[i][1] + gap[i][2] * gap[i][2];
    const Lanes shear = b.k_t * b.k_t * (gap_sq - dn[i] * dn[i]);
    shear_sq[i] = zero < shear ? shear : zero;  // std::max(0, ·)
    const Lanes strength = b.cohesion - b.friction * (zero < dn[i] ? zero : dn[i]);  // min(dn, 0)
    weak |= (dn[i] > b.peak) | (shear_sq[i] > strength * strength);
  }
  // φ = ½k_t|Δ|² + ½(k_n − k_t)(Δ·n)²; v = Σ w(k_n − k_t)(Δ·n)·(I − nnᵀ)Δ is the energy's pull on
  // n.
  const Lanes k_nt = b.k_n - b.k_t;
  Lanes v[3] = {zero, zero, zero};
  b.stored_energy = zero;
  for (int i = 0; i < 3; ++i) {
    const Lanes along = k_nt * dn[i];
    const Lanes pull = b.w * k_nt * dn[i];
    for (int k = 0; k < 3; ++k) {
      const Lanes traction = b.k_t * gap[i][k] + along * n[k];
      b.force[3 * i + k] = zero + b.w * traction;
      b.force[9 + 3 * i + k] = zero - b.w * traction;
      v[k] += pull * (gap[i][k] - dn[i] * n[k]);
    }
    b.stored_energy += b.w * (half * b.k_n * dn[i] * dn[i] + half * shear_sq[i] / b.k_t);
  }
  // δψ = v·δN/|N| with δN = δe × g + e × δg; each node takes half of its mid-point's gradient.
  const Lanes grad_e[3] = {(g[1] * v[2] - g[2] * v[1]) * inv_n_len,
                           (g[2] * v[0] - g[0] * v[2]) * inv_n_len,
                           (g[0] * v[1] - g[1] * v[0]) * inv_n_len};
  const Lanes grad_g[3] = {(v[1] * e[2] - v[2] * e[1]) * inv_n_len,
                           (v[2] * e[0] - v[0] * e[2]) * inv_n_len,
                           (v[0] * e[1] - v[1] * e[0]) * inv_n_len};
  for (int k = 0; k < 3; ++k) {
    const Lanes grad_m[3] = {-grad_e[k] - grad_g[k], grad_e[k], grad_g[k]};
    for (int i = 0; i < 3; ++i) {
      b.force[3 * i + k] -= half * grad_m[i];
      b.force[9 + 3 * i + k] -= half * grad_m[i];
    }
  }
  for (int c = 0; c < 18; ++c) b.force[c] = flat ? zero : b.force[c];  // no area, no force
  b.stored_energy = flat ? zero : b.stored_energy;
  for (int l = 0; l < intact_lanes; ++l)
    b.step[l] = flat[l] ? IntactStep::degenerate : weak[l] ? IntactStep::leaves : IntactStep::done;
}

// intact_joint_steps as built for this CPU: AVX2 (one instruction for the four lanes) where the
// CPU has it, else the x86-64 baseline (two); chosen when the program loads.  AVX2 without FMA
// rounds every operation as the baseline does, so both give the same bits: the kernel test checks
// that through this function, and the joint stage, whose loop is built the same two ways
// (JointStage::add_forces), relies on it.
void intact_joint_steps_for_this_cpu(IntactJointBatch& batch);

}  // namespace fdem
