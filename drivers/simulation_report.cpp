// Simulation::report: the run's counts, energies, timings, decomposition and memory, reduced over
// the ranks (summary.json and the stage table).
#include <algorithm>
#include <chrono>

#include "contact/contact_stage.hpp"
#include "core/model.hpp"
#include "core/state_hash.hpp"
#include "drivers/process_memory.hpp"
#include "drivers/simulation.hpp"
#include "fracture/joint_stage.hpp"
#include "parallel/communicator.hpp"
#include "parallel/distribution.hpp"

namespace fdem {

RunReport Simulation::report() const {
  RunReport r;
  r.steps = steps_;
  r.time = time_;
  r.time_step = dt_;
  r.critical_time_step = dt_critical_;
  r.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
  r.energy = ledger_.current();
  r.balance_error = ledger_.balance_error();
  for (const auto& c : clocks_) r.stages.push_back(c);
  r.pieces = static_cast<long>(model_.pieces.size());
  if (scene_.quasi_static.kinetic()) r.kinetic_damping_stops = kinetic_damping_stops_;
  // Counts of what this rank owns (joints: by their tet A), summed over the ranks below.
  std::vector<std::int64_t> counts = {model_.nodes.n_owned, 0, 0, 0, 0, 0, 0};
  for (LocalIndex t = 0; t < model_.tets.size(); ++t) counts[1] += model_.tets.is_owned(t);
  const JointArrays& joint_rows = model_.joints;
  for (LocalIndex i = 0; i < joint_rows.size(); ++i) {
    if (!model_.tets.is_owned(joint_rows.tets[2 * i])) continue;
    ++counts[2];
    const double f_t =
        model_.joint_laws[static_cast<std::size_t>(joint_rows.law[i])].fracture.tensile_strength;
    r.joint_tensile_min = std::min(r.joint_tensile_min, f_t);
    r.joint_tensile_max = std::max(r.joint_tensile_max, f_t);
    if (!joint_rows.broken[i]) continue;
    ++counts[3];
    const auto mode = static_cast<FailureMode>(joint_rows.mode[i]);
    ++counts[4 + (mode == FailureMode::tension ? 0 : mode == FailureMode::shear ? 1 : 2)];
  }
  std::vector<std::int64_t> memory = {startup_peak_rss_kib_, peak_rss_kib()};
  r.startup_peak_rss_kib_max = r.startup_peak_rss_kib_mean = memory[0];
  r.run_peak_rss_kib_max = r.run_peak_rss_kib_mean = memory[1];
  // Largest gids held (every rank's are the model's, ghosts included).
  const auto last = [](const std::vector<GlobalId>& gids) {
    return gids.empty() ? GlobalId{-1} : *std::max_element(gids.begin(), gids.end());
  };
  std::vector<std::int64_t> gid_max = {last(model_.nodes.gid), last(model_.tets.gid),
                                       last(model_.joints.gid)};
  r.gid_offset = model_.gid_offset;
  r.initial_equilibrium_residual = initial_residual_;
  if (distribution_) {
    std::vector<std::int64_t> largest = memory;
    largest.insert(largest.end(), gid_max.begin(), gid_max.end());
    comm_->max_in_place(largest);
    std::copy(largest.begin() + 2, largest.end(), gid_max.begin());
    comm_->sum_in_place(memory);
    r.startup_peak_rss_kib_max = largest[0];
    r.run_peak_rss_kib_max = largest[1];
    r.startup_peak_rss_kib_mean = memory[0] / comm_->size();
    r.run_peak_rss_kib_mean = memory[1] / comm_->size();
    comm_->sum_in_place(counts);
    r.ranks = comm_->size();
    r.state_hash = hash_to_hex(global_state_hash(model_, *comm_));
    r.joint_strength_hash = hash_to_hex(comm_->sum(joint_strength_hash(model_)));
    r.joint_tensile_min = comm_->min(r.joint_tensile_min);
    r.joint_tensile_max = comm_->max(r.joint_tensile_max);
    r.fragments = global_fragment_count(model_, *comm_);
    distribution_->close_report();
    const DistributionReport& d = distribution_->report();
    r.parallel = true;
    r.start = distributed_start_ ? "distributed" : "whole_model";
    r.imbalance = d.imbalance;
    r.max_imbalance = d.max_imbalance;
    r.redistributions = d.cycles;
    r.rebalances = d.rebalances;
    r.migrated_elements = d.migrated_tets;
    r.halo_elements_max = d.halo_tets_max;
    r.ghost_nodes_max = d.ghost_nodes_max;
    r.ghost_nodes_mean = d.ghost_nodes_sum / comm_->size();
    r.neighbours_max = d.neighbours_max;
    r.exchanged_ghosts_max = d.exchanged_ghosts_max;
    r.exchanged_ghosts_mean = d.exchanged_ghosts_sum / comm_->size();
    r.migration = d.migration;
    r.active_elements_max = comm_->max(static_cast<std::int64_t>(model_.tet_force_order.size()));
    r.communication_seconds =
        clocks_[halo].seconds + clocks_[migration].seconds + reduction_seconds_;
  } else {
    r.state_hash = hash_to_hex(state_hash(model_.nodes, model_.gid_offset));
    r.joint_strength_hash = hash_to_hex(joint_strength_hash(model_));
    r.fragments = count_fragments(model_);
  }
  r.node_gid_max = gid_max[0];
  r.tet_gid_max = gid_max[1];
  r.joint_gid_max = gid_max[2];
  r.nodes = counts[0];
  r.elements = counts[1];
  r.joints = counts[2];
  r.broken_joints = counts[3];
  for (int m = 0; m < 3; ++m) r.broken_by_mode[m] = counts[4 + m];
  return r;
}

}  // namespace fdem
