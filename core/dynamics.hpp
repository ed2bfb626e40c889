// Element-loop stages of the step: internal forces, gathering corner forces to nodes in canonical
// order, gravity, and the central-difference update with its energy bookkeeping.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "core/model.hpp"
#include "core/piece_moments.hpp"

namespace fdem {

struct InternalForceSummary {
  double strain_energy = 0.0;  // J, at the current positions
  double damping_power = 0.0;  // W, viscous dissipation rate
  double min_jacobian = 1.0;   // smallest det F over the tets
  LocalIndex min_jacobian_tet = -1;
};

// Sets every node's force to the sum of its tets' internal forces, added in ascending tet global
// id (model.tet_force_order) so the sum is the same whatever the local layout or rank.
InternalForceSummary compute_internal_forces(Model& model);

// Split phase for parallel runs: the tets that need no ghost node are computed while the ghost
// exchange is in flight; `complete_halo` is called after them, then the tets with a ghost node.
// Every node still receives its contributions in ascending tet gid: the sums of "boundary" nodes
// (touched by a tet with a ghost node) wait in a per-corner buffer and are added in gid order at
// the end, so the result is bit-identical to compute_internal_forces.
struct InternalForceSplit {
  std::vector<LocalIndex> early;          // active tets without a ghost node, ascending gid
  std::vector<LocalIndex> late;           // active tets with a ghost node, ascending gid
  std::vector<LocalIndex> boundary_tets;  // active tets touching a boundary node, ascending gid
  std::vector<std::uint8_t> boundary;     // per node: its sum waits for the late tets
  std::vector<LocalIndex> corner_slot;    // per tet: its row in corner_force, or -1
  std::vector<double> corner_force;       // 12 per boundary tet (N), scratch
};
// Call after every change of the local model (distribution).
void build_internal_force_split(const Model& model, InternalForceSplit& split);
// `gravity` (m/s², optional): the forces start from each node's weight m·g instead of 0 — the
// terms of add_gravity, added first instead of last, in one pass over the forces instead of two.
InternalForceSummary compute_internal_forces(Model& model, InternalForceSplit& split,
                                             const std::function<void()>& complete_halo,
                                             const Vec3* gravity = nullptr);

// Adds m·g to every node's force.
void add_gravity(const Vec3& gravity, NodeArrays& nodes);

struct IntegrationSummary {
  double kinetic_energy = 0.0;  // J, ½m·v⁻·v⁺ (the energy central difference conserves)
  double constraint_work_before = 0.0;  // J, reactions at prescribed components · (x_n − x_n−1)/2
  double constraint_work_after = 0.0;     // J, reactions · (x_n+1 − x_n)/2
  double kinetic_energy_half_step = 0.0;  // J, ½m|v_n+½|² (grows in an unstable run)
  Vec3 momentum_before = Vec3::Zero();    // Σ m·v_n−½ (kg m/s), for the work of uniform loads
  Vec3 momentum_after = Vec3::Zero();     // Σ m·v_n+½
  double damping_work_before = 0.0;  // J, quasi-static damping forces · (x_n − x_n−1)/2 (≤ 0)
  double damping_work_after = 0.0;   // J, quasi-static damping forces · (x_n+1 − x_n)/2
  // In quasi-static steps only (the mode's equilibrium test), over the owned nodes: the
  // unbalanced force Σ|f_k| over free components, the supports' Σ|f_k| over prescribed ones (N),
  // and the mass (kg).
  double unbalanced_force = 0.0, support_force = 0.0, mass = 0.0;
  // m, largest |Δx| of a node this step (+inf if one is NaN; the tunnelling guard), and that node
  // (−1 when none moved).
  double max_displacement_increment = 0.0;
  LocalIndex fastest_node = -1;
  double largest_coordinate = 0.0;  // m, largest |x| component after the step (its rounding)
  bool finite = true;               // false if any velocity became NaN or infinite
};

// The quasi-static mode's part in one step (core/scene.hpp, QuasiStaticSpec); {} is a dynamic
// step.
struct StepDamping {
  bool quasi_static = false;  // sum the unbalanced and support forces (the equilibrium test)
  double local = 0.0;         // α of local damping; 0: none
  bool stop_motion = false;   // kinetic damping: every free component ends the step at rest
};

// Central difference: v⁺ = v⁻ + dt·f/m (prescribed components set), x += dt·v⁺, on owned nodes.
// With local damping α > 0 (Cundall's non-viscous damping, quasi-static runs) every free component
// is driven by f − α·|f|·sign(v⁻) instead of f: the unbalanced force is reduced by the fraction α
// while a node moves with it and enlarged while it moves against it, whatever the mass or
// frequency.  With stop_motion every free component whose velocity keeps its sign gets the force
// −m·v⁺/dt more, which leaves it at rest (v⁺ = 0, x_n+1 = x_n) and takes ½m·v⁻·v⁺ ≥ 0 from the
// energy central difference conserves; one whose velocity turns is left as it is (stopping it
// would add energy).  The damping's work is returned for the energy balance.
IntegrationSummary integrate_central_difference(double dt, NodeArrays& nodes,
                                                const StepDamping& damping = {});

// Kinetic damping's decision for the next step from the kinetic energy ½m|v|² (J) of the last two
// half steps: the energy fell, so it peaked in the last step, and the next step stops every free
// node about there (where the bodies are near their least potential energy along the motion).
// After a stop the energy restarts from 0, so never two stops running; a motion that keeps
// speeding up (a mechanism) is never stopped.
inline bool kinetic_energy_peaked(double before, double last, bool stopped_last) {
  return !stopped_last && last < before;
}

// Mass-weighted position, velocity and rotation of every piece of a model held whole by one
// process, indexed by piece id (exact sums: core/piece_moments; on N ranks
// parallel/piece_directory gives the same values).
std::vector<PieceMotion> piece_motions(const Model& model);

// Total linear and angular momentum (about the origin) of the owned nodes.
Vec3 linear_momentum(const NodeArrays& nodes);
Vec3 angular_momentum(const NodeArrays& nodes);

}  // namespace fdem
