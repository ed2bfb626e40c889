// The Simulation's checks of boundaries and initial state at start-up: every absorbing entry
// selects faces, and the equilibrium residual of the initial stress at t = 0.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/dynamics.hpp"
#include "core/error.hpp"
#include "core/initial_stress.hpp"
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
