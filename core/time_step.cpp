#include "core/time_step.hpp"

#include <limits>

#include "core/tet_kernels.hpp"

namespace fdem {

CriticalStep critical_time_step(const Model& model) {
  const TetArrays& tets = model.tets;
  const NodeArrays& nodes = model.nodes;
  const LocalIndex n_tets = tets.size();

  // The current shape of tet t (recomputed in pass 2 rather than stored: 80 B per tet).
  const auto current_shape = [&](LocalIndex t) {
    Vec3 x[4];
    for (int c = 0; c < 4; ++c) x[c] = vec3_at(nodes.x.data(), tets.nodes[4 * t + c]);
    return tet_reference(x);
  };
  // Pass 1: each tet's stiffness weight (its largest K eigenvalue, N/m) and the weight per node.
  std::vector<double> weight(n_tets, 0.0), node_weight(nodes.size(), 0.0);
  for (LocalIndex t = 0; t < n_tets; ++t) {
    const TetReference current = current_shape(t);
    if (!(current.volume > 0.0)) continue;  // inverted: the force stage reports it
    weight[t] = tet_max_stiffness_eigenvalue(current.dm_inv, current.volume,
                                             model.materials[tets.material[t]].lame);
    for (int c = 0; c < 4; ++c) node_weight[tets.nodes[4 * t + c]] += weight[t];
  }

  // Pass 2: λ_max(M_e⁻¹K_e) with the node masses split in proportion to the weights.
  CriticalStep out;
  out.dt = std::numeric_limits<double>::infinity();
  for (LocalIndex t = 0; t < n_tets; ++t) {
    // Each tet counts once, on its owner (whose halo holds every tet around its nodes).
    if (weight[t] <= 0.0 || !tets.is_owned(t)) continue;
    double corner_mass[4];
    for (int c = 0; c < 4; ++c) {
      const LocalIndex n = tets.nodes[4 * t + c];
      corner_mass[c] = nodes.mass[n] * weight[t] / node_weight[n];
    }
    const MaterialProperties& mat = model.materials[tets.material[t]];
    const TetReference current = current_shape(t);
    const double omega =
        std::sqrt(tet_max_eigenvalue(current.dm_inv, current.volume, mat.lame, corner_mass));
    const double dt = critical_step_for_frequency(omega, mat.damping_ratio);
    if (dt < out.dt) {
      out.dt = dt;
      out.limiting_tet = t;
    }
  }
  return out;
}

}  // namespace fdem
