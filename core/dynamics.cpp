#include "core/dynamics.hpp"

#include <cmath>
#include <limits>

#include "core/tet_force_kernel.hpp"

namespace fdem {

namespace {

// What the element loop hands a scatter: tet t's force on corner c (node n), in N.
using CornerForce = const double (&)[3];

// The scatter that adds each corner force to its node's force in f (N).
inline auto added_to(double* f) {
  return [f](LocalIndex, int, LocalIndex n, CornerForce force) {
    for (int k = 0; k < 3; ++k) f[3 * static_cast<std::size_t>(n) + k] += force[k];
  };
}

// One tet's result into the summary, in the order the tets are computed.
inline void add_to_summary(const TetArrays& tets, LocalIndex t, double strain_energy,
                           double damping_power, double jacobian, InternalForceSummary& sum) {
  if (tets.is_owned(t)) {  // halo tets are computed for their forces; their owner reports them
    sum.strain_energy += strain_energy;
    sum.damping_power += damping_power;
  }
  if (!(jacobian >= sum.min_jacobian)) {  // NaN counts as worst
    sum.min_jacobian = jacobian;
    sum.min_jacobian_tet = t;
  }
}

template <class Scatter>
void add_one_tet(const Model& model, LocalIndex t, InternalForceSummary& sum, Scatter& scatter) {
  const TetArrays& tets = model.tets;
  const double* x = model.nodes.x.data();
  const double* v = model.nodes.v.data();
  const MaterialProperties& material = model.materials[tets.material[t]];
  const double viscosity = tets.viscosity[t];
  const LocalIndex* corner_node = tets.nodes.data() + 4 * static_cast<std::size_t>(t);
  double xs[4][3], vs[4][3] = {}, dm_inv[9];
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 3; ++k) {
      xs[c][k] = x[3 * static_cast<std::size_t>(corner_node[c]) + k];
      if (viscosity > 0.0) vs[c][k] = v[3 * static_cast<std::size_t>(corner_node[c]) + k];
    }
  for (int e = 0; e < 9; ++e) dm_inv[e] = tets.dm_inv[9 * static_cast<std::size_t>(t) + e];
  TetCornerForces<double> out;
  const double lambda = material.lame.lambda, mu = material.lame.mu;
  if (material.model == ElasticModel::neo_hookean)
    tet_corner_forces(xs, vs, dm_inv, tets.volume0[t], NeoHookeanLaw<double>{lambda, mu}, viscosity,
                      viscosity > 0.0, out);
  else
    tet_corner_forces(xs, vs, dm_inv, tets.volume0[t], StVenantKirchhoffLaw<double>{lambda, mu},
                      viscosity, viscosity > 0.0, out);
  for (int c = 0; c < 4; ++c) scatter(t, c, corner_node[c], out.force[c]);
  add_to_summary(tets, t, out.strain_energy, out.damping_power, out.jacobian, sum);
}

// Four tets of one elastic model side by side (core/tet_force_kernel.hpp); their forces are then
// scattered tet by tet in the given order, so every node sums its contributions as one tet at a
// time would.
template <class Scatter>
void add_four_tets(const Model& model, const LocalIndex (&t)[lane_count], ElasticModel law,
                   TetLaneBatch& b, InternalForceSummary& sum, Scatter& scatter) {
  const TetArrays& tets = model.tets;
  const double* x = model.nodes.x.data();
  const double* v = model.nodes.v.data();
  const LocalIndex* node[lane_count];
  for (int l = 0; l < lane_count; ++l)
    node[l] = tets.nodes.data() + 4 * static_cast<std::size_t>(t[l]);
  const auto gather = [&](const double* values, Lanes(&into)[4][3]) {
    for (int c = 0; c < 4; ++c) {
      const double* p[lane_count];
      for (int l = 0; l < lane_count; ++l) p[l] = values + 3 * static_cast<std::size_t>(node[l][c]);
      for (int k = 0; k < 3; ++k) into[c][k] = Lanes{p[0][k], p[1][k], p[2][k], p[3][k]};
    }
  };
  const auto per_tet = [&](const std::vector<double>& values, std::size_t width, int e) {
    const auto at = [&](int l) { return values[width * static_cast<std::size_t>(t[l]) + e]; };
    return Lanes{at(0), at(1), at(2), at(3)};
  };
  gather(x, b.x);
  for (int e = 0; e < 9; ++e) b.dm_inv[e] = per_tet(tets.dm_inv, 9, e);
  b.volume0 = per_tet(tets.volume0, 1, 0);
  b.viscosity = per_tet(tets.viscosity, 1, 0);
  b.any_viscous = false;
  for (int l = 0; l < lane_count; ++l) b.any_viscous = b.any_viscous || b.viscosity[l] > 0.0;
  if (b.any_viscous) gather(v, b.v);
  const auto lame = [&](int l) { return model.materials[tets.material[t[l]]].lame; };
  b.lambda = Lanes{lame(0).lambda, lame(1).lambda, lame(2).lambda, lame(3).lambda};
  b.mu = Lanes{lame(0).mu, lame(1).mu, lame(2).mu, lame(3).mu};
  if (law == ElasticModel::neo_hookean)
    neo_hookean_tet_lanes(b);
  else
    st_venant_kirchhoff_tet_lanes(b);
  for (int l = 0; l < lane_count; ++l) {
    for (int c = 0; c < 4; ++c) {
      const double force[3] = {b.out.force[c][0][l], b.out.force[c][1][l], b.out.force[c][2][l]};
      scatter(t[l], c, node[l][c], force);
    }
    add_to_summary(tets, t[l], b.out.strain_energy[l], b.out.damping_power[l], b.out.jacobian[l],
                   sum);
  }
}

// The internal forces of the tets listed, in list order: four at a time where four consecutive
// tets share an elastic model, else one by one.  scatter(t, c, n, force) takes each corner force.
template <class Scatter>
void add_tet_forces(const Model& model, const LocalIndex* list, std::size_t count,
                    InternalForceSummary& sum, Scatter&& scatter) {
  const TetArrays& tets = model.tets;
  TetLaneBatch batch;
  std::size_t i = 0;
  for (; i + lane_count <= count; i += lane_count) {
    const LocalIndex t[lane_count] = {list[i], list[i + 1], list[i + 2], list[i + 3]};
    const ElasticModel law = model.materials[tets.material[t[0]]].model;
    bool same = true;
    for (int l = 1; l < lane_count; ++l)
      same = same && model.materials[tets.material[t[l]]].model == law;
    if (same) {
      add_four_tets(model, t, law, batch, sum, scatter);
      continue;
    }
    for (const LocalIndex one : t) add_one_tet(model, one, sum, scatter);
  }
  for (; i < count; ++i) add_one_tet(model, list[i], sum, scatter);
}

}  // namespace

InternalForceSummary compute_internal_forces(Model& model) {
  NodeArrays& nodes = model.nodes;
  std::fill(nodes.f.begin(), nodes.f.end(), 0.0);
  InternalForceSummary sum;
  double* f = nodes.f.data();
  // Tets in ascending global id: each node receives its contributions in that one order.
  add_tet_forces(model, model.tet_force_order.data(), model.tet_force_order.size(), sum,
                 added_to(f));
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
                                             const std::function<void()>& complete_halo,
                                             const Vec3* gravity) {
  const TetArrays& tets = model.tets;
  NodeArrays& nodes = model.nodes;
  if (gravity) {
    const double g[3] = {gravity->x(), gravity->y(), gravity->z()};
    for (LocalIndex n = 0; n < nodes.size(); ++n)
      for (int k = 0; k < 3; ++k) nodes.f[3 * n + k] = nodes.mass[n] * g[k];
  } else {
    std::fill(nodes.f.begin(), nodes.f.end(), 0.0);
  }
  InternalForceSummary sum;
  double* f = nodes.f.data();
  double* corner = split.corner_force.data();
  const LocalIndex* slot = split.corner_slot.data();
  const std::uint8_t* boundary = split.boundary.data();
  const auto parked = [&](LocalIndex t, int c, CornerForce force) {
    double* to = corner + 12 * static_cast<std::size_t>(slot[t]) + 3 * c;
    for (int k = 0; k < 3; ++k) to[k] = force[k];
  };
  const auto early_scatter = [&](LocalIndex t, int c, LocalIndex n, CornerForce force) {
    if (boundary[n])
      parked(t, c, force);
    else
      added_to(f)(t, c, n, force);
  };
  const auto late_scatter = [&](LocalIndex t, int c, LocalIndex, CornerForce force) {
    parked(t, c, force);
  };
  // Interior work while the ghost positions travel (straight to the nodes when no node waits).
  if (split.boundary_tets.empty())
    add_tet_forces(model, split.early.data(), split.early.size(), sum, added_to(f));
  else
    add_tet_forces(model, split.early.data(), split.early.size(), sum, early_scatter);
  if (complete_halo) complete_halo();
  add_tet_forces(model, split.late.data(), split.late.size(), sum, late_scatter);
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

// The step's sums over nodes that IntegrationSummary holds only once finished.
struct IntegrationSums {
  double kinetic2 = 0.0, kinetic_half2 = 0.0;
  double damping_power_old = 0.0, damping_power_new = 0.0;  // W, Σ f_d·v⁻ and Σ f_d·v⁺
  double max_dx2 = 0.0;     // m², largest |Δx|² of a node (+inf once one is NaN)
  double max_abs_x = 0.0;   // m, largest |x| component after the step
  LocalIndex fastest = -1;  // its node
  // Free undamped nodes four at a time: twelve components in three vectors, lane l of vector j
  // being component (4j + l) mod 3.
  Lanes kinetic2_lanes[3] = {}, kinetic_half2_lanes[3] = {};
  Lanes momentum_before_lanes[3] = {}, momentum_after_lanes[3] = {};
  Lanes max_abs_x_lanes = {};

  void add_displacement(LocalIndex n, double dx2) {
    if (dx2 <= max_dx2) return;
    if (max_dx2 == std::numeric_limits<double>::infinity()) return;  // a NaN came first
    fastest = n;
    max_dx2 = std::isnan(dx2) ? std::numeric_limits<double>::infinity() : dx2;
  }
};

// One node of the central-difference step; `mask` its prescribed components.  `damped` and
// `constrained` are known per call.
template <bool damped, bool constrained>
inline void integrate_node(double dt, NodeArrays& nodes, LocalIndex n, std::uint8_t mask,
                           const StepDamping& damping, IntegrationSums& sum,
                           IntegrationSummary& out) {
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
    if (damped && !prescribed && (v_old != 0.0 || damping.stop_motion)) {
      // The local damping force opposes v⁻; v⁻ = 0 (a node at rest) gets none.
      double f_damping = 0.0;  // N
      if (v_old != 0.0) {
        f_damping = -damping.local * std::abs(nodes.f[i]) * (v_old > 0 ? 1.0 : -1.0);
        v_new += dt * f_damping / m;
      }
      // Kinetic damping: the force that stops it within the step takes ½m·v⁻·v⁺ from the energy
      // central difference conserves; a component whose velocity turns in this step would gain
      // (near the stability limit), so it goes on: it is at its own turning point.
      if (damping.stop_motion && v_old * v_new >= 0.0) {
        f_damping -= m * v_new / dt;
        v_new = 0.0;
      }
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
    sum.max_abs_x = std::max(sum.max_abs_x, std::abs(nodes.x[i]));
    dx2 += dx * dx;
  }
  sum.add_displacement(n, dx2);
  if (damped) out.mass += m;
}

// Four free, undamped nodes n … n+3: their twelve components as three vectors, with each
// component's arithmetic that of integrate_node (the same bits of x and v).
inline void integrate_four_free_nodes(double dt, NodeArrays& nodes, LocalIndex n,
                                      IntegrationSums& sum) {
  const double* m = nodes.mass.data() + n;
  const Lanes mass[3] = {
      {m[0], m[0], m[0], m[1]}, {m[1], m[1], m[2], m[2]}, {m[2], m[3], m[3], m[3]}};
  double* v = nodes.v.data() + 3 * static_cast<std::size_t>(n);
  double* x = nodes.x.data() + 3 * static_cast<std::size_t>(n);
  const double* f = nodes.f.data() + 3 * static_cast<std::size_t>(n);
  double dx[12];
  for (int j = 0; j < 3; ++j) {
    const Lanes v_old = load_lanes(v + 4 * j), force = load_lanes(f + 4 * j);
    Lanes position = load_lanes(x + 4 * j);
    const Lanes v_new = v_old + dt * force / mass[j];
    sum.kinetic2_lanes[j] += mass[j] * v_old * v_new;
    sum.kinetic_half2_lanes[j] += mass[j] * v_new * v_new;
    sum.momentum_before_lanes[j] += mass[j] * v_old;
    sum.momentum_after_lanes[j] += mass[j] * v_new;
    const Lanes step = dt * v_new;
    position += step;
    const Lanes magnitude = position < 0.0 ? -position : position;
    sum.max_abs_x_lanes = sum.max_abs_x_lanes < magnitude ? magnitude : sum.max_abs_x_lanes;
    store_lanes(v_new, v + 4 * j);
    store_lanes(position, x + 4 * j);
    store_lanes(step, dx + 4 * j);
  }
  for (int node = 0; node < 4; ++node) {
    const double* d = dx + 3 * node;
    sum.add_displacement(n + node, (d[0] * d[0] + d[1] * d[1]) + d[2] * d[2]);
  }
}

template <bool damped>
void integrate_nodes(double dt, NodeArrays& nodes, const StepDamping& damping, IntegrationSums& sum,
                     IntegrationSummary& out) {
  LocalIndex n = 0;
  if (!damped)  // runs of four free nodes, the common case, four at a time
    for (; n + 4 <= nodes.n_owned; n += 4) {
      const std::uint8_t* mask = nodes.constrained.data() + n;
      if ((mask[0] | mask[1] | mask[2] | mask[3]) == 0) {
        integrate_four_free_nodes(dt, nodes, n, sum);
        continue;
      }
      for (LocalIndex one = n; one < n + 4; ++one)
        if (mask[one - n])
          integrate_node<false, true>(dt, nodes, one, mask[one - n], damping, sum, out);
        else
          integrate_node<false, false>(dt, nodes, one, 0, damping, sum, out);
    }
  for (; n < nodes.n_owned; ++n) {
    const std::uint8_t mask = nodes.constrained[n];
    if (mask)
      integrate_node<damped, true>(dt, nodes, n, mask, damping, sum, out);
    else
      integrate_node<damped, false>(dt, nodes, n, mask, damping, sum, out);
  }
}

#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
// The undamped loop built for AVX2 too (one instruction per vector), chosen when the program
// loads; no FMA, so both give the same bits.
__attribute__((target_clones("avx2", "default"), flatten))
#endif
void integrate_undamped_nodes(double dt, NodeArrays& nodes, IntegrationSums& sum,
                              IntegrationSummary& out) {
  integrate_nodes<false>(dt, nodes, StepDamping{}, sum, out);
}

}  // namespace

IntegrationSummary integrate_central_difference(double dt, NodeArrays& nodes,
                                                const StepDamping& damping) {
  IntegrationSummary out;
  IntegrationSums sum;
  if (damping.quasi_static)
    integrate_nodes<true>(dt, nodes, damping, sum, out);
  else
    integrate_undamped_nodes(dt, nodes, sum, out);
  // The four-node vectors' sums, lane by lane in a fixed order.
  for (int j = 0; j < 3; ++j)
    for (int l = 0; l < lane_count; ++l) {
      const int k = (4 * j + l) % 3;
      sum.kinetic2 += sum.kinetic2_lanes[j][l];
      sum.kinetic_half2 += sum.kinetic_half2_lanes[j][l];
      out.momentum_before[k] += sum.momentum_before_lanes[j][l];
      out.momentum_after[k] += sum.momentum_after_lanes[j][l];
    }
  out.damping_work_before = 0.5 * dt * sum.damping_power_old;
  out.damping_work_after = 0.5 * dt * sum.damping_power_new;
  out.kinetic_energy = 0.5 * sum.kinetic2;
  out.kinetic_energy_half_step = 0.5 * sum.kinetic_half2;
  out.max_displacement_increment = std::sqrt(sum.max_dx2);
  out.fastest_node = sum.fastest;
  out.largest_coordinate = sum.max_abs_x;
  for (int l = 0; l < lane_count; ++l)
    out.largest_coordinate = std::max(out.largest_coordinate, sum.max_abs_x_lanes[l]);
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
