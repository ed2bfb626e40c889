#include "core/time_step.hpp"

#include <limits>

#include "core/tet_kernels.hpp"

namespace fdem {

CriticalStep critical_time_step(const Model& model) {
  const TetArrays& tets = model.tets;
  const NodeArrays& nodes = model.nodes;
  CriticalStep out;
  out.dt = std::numeric_limits<double>::infinity();
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    Vec3 x[4];
    for (int c = 0; c < 4; ++c) x[c] = vec3_at(nodes.x.data(), tets.nodes[4 * t + c]);
    const TetReference current = tet_reference(x);
    if (!(current.volume > 0.0)) {  // inverted: the caller reports it from the force stage
      continue;
    }
    const MaterialProperties& mat = model.materials[tets.material[t]];
    const double k_max = tet_max_stiffness_eigenvalue(current.dm_inv, current.volume, mat.lame);
    const double dt =
        tet_critical_time_step(k_max, mat.density, tets.volume0[t], mat.damping_ratio);
    if (dt < out.dt) {
      out.dt = dt;
      out.limiting_tet = t;
    }
  }
  return out;
}

}  // namespace fdem
