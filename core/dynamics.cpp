#include "core/dynamics.hpp"

#include <cmath>

#include "core/tet_kernels.hpp"

namespace fdem {

namespace {

// The per-tet kernel is too large for the compiler's inlining heuristics; inlining it into the
// element loop anyway (GCC, Clang) saves the call and the TetForce copy: ~5-10 % on the stage.
#if defined(__GNUC__)
#define FDEM_INLINE_CALLEES __attribute__((flatten))
#else
#define FDEM_INLINE_CALLEES
#endif

template <class Material, class Scatter>
FDEM_INLINE_CALLEES inline void add_tet_force(const TetArrays& tets, LocalIndex t,
                                              const Material& material, NodeArrays& nodes,
                                              InternalForceSummary& sum, Scatter&& scatter) {
  const double viscosity = tets.viscosity[t];
  const LocalIndex* corner_node = tets.nodes.data() + 4 * static_cast<std::size_t>(t);
  Vec3 x[4], v[4];
  for (int c = 0; c < 4; ++c) x[c] = vec3_at(nodes.x.data(), corner_node[c]);
  // The kernel reads velocities only for viscous damping: skip that gather when undamped.
  for (int c = 0; c < 4; ++c)
    v[c] = viscosity > 0.0 ? Vec3(vec3_at(nodes.v.data(), corner_node[c])) : Vec3::Zero();
  const Eigen::Map<const Mat3> dm_inv(tets.dm_inv.data() + 9 * static_cast<std::size_t>(t));
  const TetForce out = tet_internal_force(x, v, dm_inv, tets.volume0[t], material, viscosity);
  for (int c = 0; c < 4; ++c) scatter(c, corner_node[c], out.force[c]);
  if (tets.is_owned(t)) {  // halo tets are computed for their forces; their owner reports them
    sum.strain_energy += out.strain_energy;
    sum.damping_power += out.damping_power;
  }
  if (!(out.jacobian >= sum.min_jacobian)) {  // NaN counts as worst
    sum.min_jacobian = out.jacobian;
    sum.min_jacobian_tet = t;
  }
}

// Runs `body(material)` with the tet's material law as a value type.
template <class Body>
inline void with_material(const MaterialProperties& mat, Body&& body) {
  if (mat.model == ElasticModel::neo_hookean)
    body(NeoHookean{mat.lame});
  else
    body(StVenantKirchhoff{mat.lame});
}

}  // namespace

InternalForceSummary compute_internal_forces(Model& model) {
  const TetArrays& tets = model.tets;
  NodeArrays& nodes = model.nodes;
  std::fill(nodes.f.begin(), nodes.f.end(), 0.0);
  InternalForceSummary sum;
  double* f = nodes.f.data();
  const auto add_to_node = [f](int, LocalIndex n, const Vec3& force) { vec3_at(f, n) += force; };
  // Tets in ascending global id: each node receives its contributions in that one order.
  for (const LocalIndex t : model.tet_force_order)
    with_material(model.materials[tets.material[t]], [&](const auto& material) {
      add_tet_force(tets, t, material, nodes, sum, add_to_node);
    });
  return sum;
}

void build_internal_force_split(const Model& model, InternalForceSplit& split) {
  const TetArrays& tets = model.tets;
  const NodeArrays& nodes = model.nodes;
  split.early.clear();
  split.late.clear();
  split.boundary_tets.clear();
  split.boundary.assign(static_cast<std::size_t>(nodes.size()), 0);
  for (const LocalIndex t : model.tet_force_order) {
    bool ghost = false;
    for (int c = 0; c < 4; ++c) ghost = ghost || tets.nodes[4 * t + c] >= nodes.n_owned;
    (ghost ? split.late : split.early).push_back(t);
    if (ghost)
      for (int c = 0; c < 4; ++c) split.boundary[tets.nodes[4 * t + c]] = 1;
  }
  split.corner_slot.assign(static_cast<std::size_t>(tets.size()), -1);
  for (const LocalIndex t : model.tet_force_order) {
    bool touches = false;
    for (int c = 0; c < 4; ++c) touches = touches || split.boundary[tets.nodes[4 * t + c]];
    if (!touches) continue;
    split.corner_slot[t] = static_cast<LocalIndex>(split.boundary_tets.size());
    split.boundary_tets.push_back(t);
  }
  // Only tets touching a boundary node park their corner forces (12 doubles each).
  split.corner_force.assign(12 * split.boundary_tets.size(), 0.0);
}

InternalForceSummary compute_internal_forces(Model& model, InternalForceSplit& split,
                                             const std::function<void()>& complete_halo) {
  const TetArrays& tets = model.tets;
  NodeArrays& nodes = model.nodes;
  std::fill(nodes.f.begin(), nodes.f.end(), 0.0);
  InternalForceSummary sum;
  double* f = nodes.f.data();
  double* corner = split.corner_force.data();
  const LocalIndex* slot = split.corner_slot.data();
  const std::uint8_t* boundary = split.boundary.data();
  LocalIndex t = 0;  // the tet being computed, for the scatters below
  const auto parked = [&](int c) {
    return Eigen::Map<Vec3>(corner + 12 * static_cast<std::size_t>(slot[t]) + 3 * c);
  };
  const auto early_scatter = [&](int c, LocalIndex n, const Vec3& force) {
    if (boundary[n])
      parked(c) = force;
    else
      vec3_at(f, n) += force;
  };
  const auto late_scatter = [&](int c, LocalIndex, const Vec3& force) { parked(c) = force; };
  // Interior work while the ghost positions travel.
  for (const LocalIndex e : split.early) {
    t = e;
    with_material(model.materials[tets.material[t]], [&](const auto& material) {
      add_tet_force(tets, t, material, nodes, sum, early_scatter);
    });
  }
  if (complete_halo) complete_halo();
  for (const LocalIndex l : split.late) {
    t = l;
    with_material(model.materials[tets.material[t]], [&](const auto& material) {
      add_tet_force(tets, t, material, nodes, sum, late_scatter);
    });
  }
  // Boundary nodes: every contribution, in ascending tet gid.
  for (std::size_t k = 0; k < split.boundary_tets.size(); ++k) {
    const LocalIndex b = split.boundary_tets[k];
    for (int c = 0; c < 4; ++c) {
      const LocalIndex n = tets.nodes[4 * b + c];
      if (boundary[n]) vec3_at(f, n) += Eigen::Map<const Vec3>(corner + 12 * k + 3 * c);
    }
  }
  return sum;
}

void add_gravity(const Vec3& gravity, NodeArrays& nodes) {
  for (LocalIndex n = 0; n < nodes.size(); ++n)
    for (int k = 0; k < 3; ++k) nodes.f[3 * n + k] += nodes.mass[n] * gravity[k];
}

namespace {

// The step's sums over nodes that IntegrationSummary holds only once finished, in node order (the
// same order whatever path a node takes).
struct IntegrationSums {
  double kinetic2 = 0.0, kinetic_half2 = 0.0, max_dx2 = 0.0;
  double damping_power_old = 0.0, damping_power_new = 0.0;  // W, Σ f_d·v⁻ and Σ f_d·v⁺
};

// One node of the central-difference step; `mask` its prescribed components.  `damped` and
// `constrained` are known per call, so the common node (undamped, free) runs without a test per
// component.
template <bool damped, bool constrained>
inline void integrate_node(double dt, NodeArrays& nodes, LocalIndex n, std::uint8_t mask,
                           double local_damping, IntegrationSums& sum, IntegrationSummary& out) {
  const double m = nodes.mass[n];
  double dx2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const std::size_t i = 3 * static_cast<std::size_t>(n) + k;
    const bool prescribed = constrained && (mask & (1u << k));
    const double v_old = nodes.v[i];
    double v_new = v_old + dt * nodes.f[i] / m;
    if (damped) {  // quasi-static runs: the forces of the unbalanced-force ratio
      if (prescribed)
        out.support_force += std::abs(nodes.f[i]);
      else
        out.unbalanced_force += std::abs(nodes.f[i]);
    }
    if (damped && !prescribed && v_old != 0.0) {
      // The damping force opposes v⁻; v⁻ = 0 (a node at rest) gets none.
      const double f_damping = -local_damping * std::abs(nodes.f[i]) * (v_old > 0 ? 1.0 : -1.0);
      v_new += dt * f_damping / m;
      sum.damping_power_old += f_damping * v_old;
      sum.damping_power_new += f_damping * v_new;
    }
    if (prescribed) {
      v_new = nodes.prescribed_velocity_at(i);
      const double reaction = m * (v_new - v_old) / dt - nodes.f[i];
      out.constraint_work_before += 0.5 * reaction * dt * v_old;
      out.constraint_work_after += 0.5 * reaction * dt * v_new;
    }
    sum.kinetic2 += m * v_old * v_new;
    sum.kinetic_half2 += m * v_new * v_new;
    out.momentum_before[k] += m * v_old;
    out.momentum_after[k] += m * v_new;
    nodes.v[i] = v_new;
    const double dx = dt * v_new;
    nodes.x[i] += dx;
    dx2 += dx * dx;
  }
  sum.max_dx2 = std::max(sum.max_dx2, dx2);
  if (damped) out.mass += m;
}

template <bool damped>
void integrate_nodes(double dt, NodeArrays& nodes, double local_damping, IntegrationSums& sum,
                     IntegrationSummary& out) {
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) {
    const std::uint8_t mask = nodes.constrained[n];
    if (mask)
      integrate_node<damped, true>(dt, nodes, n, mask, local_damping, sum, out);
    else
      integrate_node<damped, false>(dt, nodes, n, mask, local_damping, sum, out);
  }
}

}  // namespace

IntegrationSummary integrate_central_difference(double dt, NodeArrays& nodes,
                                                double local_damping) {
  IntegrationSummary out;
  IntegrationSums sum;
  if (local_damping > 0.0)
    integrate_nodes<true>(dt, nodes, local_damping, sum, out);
  else
    integrate_nodes<false>(dt, nodes, local_damping, sum, out);
  out.local_damping_work_before = 0.5 * dt * sum.damping_power_old;
  out.local_damping_work_after = 0.5 * dt * sum.damping_power_new;
  out.kinetic_energy = 0.5 * sum.kinetic2;
  out.kinetic_energy_half_step = 0.5 * sum.kinetic_half2;
  out.max_displacement_increment = std::sqrt(sum.max_dx2);
  out.finite = std::isfinite(sum.kinetic2);
  return out;
}

std::vector<PieceMotion> piece_motions(const Model& model) {
  const OwnedPieces owned = owned_pieces(model.nodes);
  std::vector<PieceMotion> motion(model.pieces.size());
  for (std::size_t i = 0; i < owned.ids.size(); ++i) {
    const PieceCentres c = centres_of(piece_moments(model.nodes, owned, i));
    PieceMotion& m = motion[static_cast<std::size_t>(owned.ids[i])];
    m.centroid = c.centroid;
    m.velocity = c.velocity;
    m.rotation = rotation_of(piece_spread(model.nodes, owned, i, c));
  }
  return motion;
}

Vec3 linear_momentum(const NodeArrays& nodes) {
  Vec3 p = Vec3::Zero();
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) p += nodes.mass[n] * vec3_at(nodes.v.data(), n);
  return p;
}

Vec3 angular_momentum(const NodeArrays& nodes) {
  Vec3 l = Vec3::Zero();
  for (LocalIndex n = 0; n < nodes.n_owned; ++n)
    l += nodes.mass[n] * vec3_at(nodes.x.data(), n).cross(vec3_at(nodes.v.data(), n));
  return l;
}

}  // namespace fdem
