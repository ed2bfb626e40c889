// The Simulation's checks of boundaries, loads and initial state at start-up: every absorbing
// entry selects faces, every surface and region velocity load acts on something, and the
// equilibrium residual of the initial stress at t = 0.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/dynamics.hpp"
#include "core/error.hpp"
#include "core/initial_stress.hpp"
#include "core/model_builder.hpp"
#include "drivers/simulation.hpp"
#include "parallel/communicator.hpp"

namespace fdem {

// The forces at t = 0 with the initial stress (elastic, initial stress, gravity) over the free
// components, against the initial stress's alone: the relative equilibrium residual.  The step
// recomputes every force, so the model's forces may be overwritten here.
void Simulation::check_initial_equilibrium(bool distributed) {
  compute_internal_forces(model_);
  std::fill(model_.nodes.f.begin(), model_.nodes.f.end(), 0.0);
  add_initial_stress_forces(initial_stress_, model_);
  const std::vector<double> stress_force = model_.nodes.f;
  compute_internal_forces(model_);
  add_initial_stress_forces(initial_stress_, model_);
  add_gravity(model_.gravity, model_.nodes);
  const EquilibriumSums e = equilibrium_sums(model_.nodes.f, stress_force, model_.nodes);
  std::vector<double> sums = {e.residual, e.scale};
  if (distributed) comm_->sum_in_place(sums);
  initial_residual_ = sums[1] > 0.0 ? std::sqrt(sums[0] / sums[1]) : 0.0;
}

// A load that acts on nothing is a mistake in the scene (a region beside the model): a surface
// load without a boundary face, a prescribed velocity on a region without a node.
void Simulation::check_load_targets(bool distributed) const {
  const auto global_sum = [&](std::int64_t v) { return distributed ? comm_->sum(v) : v; };
  const auto where = [&](const LoadSpec& load, std::size_t i) {  // "FILE:LINE:COLUMN: loads[i]…"
    return load.where.empty() ? scene_.source_path + ": loads[" + std::to_string(i) + "]"
                              : load.where;
  };
  for (const auto& [index, owned] : loads_->surface_face_counts())
    if (global_sum(owned) == 0) {
      const LoadSpec& load = scene_.loads[static_cast<std::size_t>(index)];
      throw InputError(where(load, static_cast<std::size_t>(index)) + ": surface load '" +
                       load.name + "' acts on no face: no boundary face " +
                       (load.region ? "has its three corners in the region's box at t = 0"
                                    : "belongs to its bodies") +
                       " (faces shared by two tets or by a joint are not boundary faces)");
    }
  for (std::size_t i = 0; i < scene_.loads.size(); ++i) {
    const LoadSpec& load = scene_.loads[i];
    if (load.kind != LoadSpec::Kind::velocity || !load.region) continue;
    if (global_sum(owned_nodes_in_region(*load.region, model_.nodes)) > 0) continue;
    std::ostringstream box;
    const auto point = [&](const Vec3& p) {
      box << "[" << p[0] << ", " << p[1] << ", " << p[2] << "]";
    };
    point(load.region->min);
    box << " .. ";
    point(load.region->max);
    throw InputError(where(load, i) + ": velocity load " +
                     (load.name.empty() ? "" : "'" + load.name + "' ") +
                     "holds no node: no node lies in its region's box " + box.str() + " at t = 0");
  }
}

void Simulation::check_absorbing_faces(bool distributed) const {
  std::vector<std::int64_t> count = absorbing_->counted_faces(model_);
  if (distributed) comm_->sum_in_place(count);
  for (std::size_t i = 0; i < count.size(); ++i) {
    if (count[i] > 0) continue;
    const RegionSpec& r = scene_.absorbing[i].region;
    std::ostringstream msg;
    msg << scene_.source_path << ": absorbing[" << i << "].region: no boundary face of the mesh"
        << (scene_.absorbing[i].bodies.empty() ? "" : " of the listed bodies")
        << " has all three nodes in the box [" << r.min.transpose() << "] – [" << r.max.transpose()
        << "] at t = 0 (faces shared by two tets or bonded by a joint are not boundary faces). "
           "Make the box enclose the outer faces that should absorb, with a margin for round-off.";
    throw InputError(msg.str());
  }
}

}  // namespace fdem
