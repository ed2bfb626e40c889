#include "core/history_sums.hpp"

#include <algorithm>

#include "core/frame_arrays.hpp"

namespace fdem {

namespace {

void add_node(const NodeArrays& nodes, LocalIndex n, GroupSums& sums) {
  const double m = nodes.mass[n];
  sums.mass.add(m);
  for (int k = 0; k < 3; ++k) sums.moment[k].add(m * (nodes.x[3 * n + k] - nodes.x0(n)[k]));
}

}  // namespace

bool load_holds_node(const LoadSpec& load, const Model& model, LocalIndex n) {
  if (load.region) {
    const Vec3 X = model.nodes.x0(n);
    return (X.array() >= load.region->min.array()).all() &&
           (X.array() <= load.region->max.array()).all();
  }
  const std::int32_t body = model.pieces.body_of(model.nodes.piece[n]);
  return std::find(load.bodies.begin(), load.bodies.end(), body) != load.bodies.end();
}

void add_load_sums(const LoadSpec& load, const Model& model, double dt, GroupSums& sums) {
  const NodeArrays& nodes = model.nodes;
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) {
    if (!load_holds_node(load, model, n)) continue;
    add_node(nodes, n, sums);
    const unsigned held = load.dof_mask & nodes.constrained[n];
    for (int k = 0; k < 3; ++k) {
      if (!(held & (1u << k))) continue;
      const std::size_t i = 3 * static_cast<std::size_t>(n) + k;
      // As integrate_central_difference books it: the impulse that sets the prescribed
      // velocity, less the forces the model puts on the node.
      sums.force[k].add(nodes.mass[n] * (nodes.prescribed_velocity_at(i) - nodes.v[i]) / dt -
                        nodes.f[i]);
    }
  }
}

void add_body_sums(std::int32_t body, const Model& model, GroupSums& sums) {
  const NodeArrays& nodes = model.nodes;
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) {
    if (model.pieces.body_of(nodes.piece[n]) != body) continue;
    add_node(nodes, n, sums);
    for (int k = 0; k < 3; ++k) sums.force[k].add(nodes.f[3 * n + k]);
  }
}

std::array<double, 4> reference_barycentric(const Model& model, LocalIndex t, const Vec3& X) {
  const LocalIndex* corner = model.tets.nodes.data() + 4 * static_cast<std::size_t>(t);
  const Eigen::Map<const Mat3> dm_inv(model.tets.dm_inv.data() + 9 * static_cast<std::size_t>(t));
  // Dm⁻¹ maps X − X0 to the coordinates along the reference edges: λ1, λ2, λ3.
  const Vec3 xi = dm_inv * (X - model.nodes.x0(corner[0]));
  return {1.0 - xi.sum(), xi.x(), xi.y(), xi.z()};
}

GlobalId owned_tet_holding(const Model& model, const Vec3& X) {
  constexpr double tolerance = 1e-9;  // of the barycentric coordinates: points on faces count
  const TetArrays& tets = model.tets;
  for (LocalIndex t = 0; t < tets.size(); ++t) {  // ascending gid: the first is the lowest
    if (!tets.is_owned(t)) continue;
    const std::array<double, 4> lambda = reference_barycentric(model, t, X);
    if (std::all_of(lambda.begin(), lambda.end(), [](double l) { return l >= -tolerance; }))
      return tets.gid[t];
  }
  return -1;
}

MonitorValues monitor_values(const Model& model, LocalIndex t, const Vec3& X) {
  const NodeArrays& nodes = model.nodes;
  const std::array<double, 4> lambda = reference_barycentric(model, t, X);
  MonitorValues out;
  for (int c = 0; c < 4; ++c) {
    const LocalIndex n = model.tets.nodes[4 * static_cast<std::size_t>(t) + c];
    out.displacement += lambda[c] * (vec3_at(nodes.x.data(), n) - nodes.x0(n));
    out.velocity += lambda[c] * vec3_at(nodes.v.data(), n);
  }
  out.stress = elastic_cauchy_stress(model, t);
  return out;
}

}  // namespace fdem
