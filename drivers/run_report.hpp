// What a run reports at its end (summary.json, drivers/run_files; the stage table): counts over
// all ranks, energies, timings, the decomposition and memory.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/energy.hpp"
#include "core/migration_report.hpp"
#include "drivers/stage_timer.hpp"

namespace fdem {

struct RunReport {
  std::string status = "running";  // completed | failed | interrupted
  std::string reason;              // message when failed or interrupted
  bool io_failure = false;         // failed: an output file could not be written (else numerical)
  long steps = 0;
  double time = 0.0;                // simulated time reached (s)
  double time_step = 0.0;           // s
  double critical_time_step = 0.0;  // s
  double wall_seconds = 0.0;
  EnergyTerms energy;
  double balance_error = 0.0;
  std::string state_hash;
  // The joints' strengths (core/state_hash: joint_strength_hash) and the range of their tensile
  // strengths (Pa; +inf/−inf without joints): the same on any rank count.
  std::string joint_strength_hash;
  // Initial stress: the relative equilibrium residual at t = 0 (−1: none given).
  double initial_equilibrium_residual = -1.0;
  double joint_tensile_min = std::numeric_limits<double>::infinity();
  double joint_tensile_max = -std::numeric_limits<double>::infinity();
  std::vector<StageClock> stages;
  // Counts over all ranks.
  int ranks = 1;
  long nodes = 0, elements = 0, pieces = 0, joints = 0, broken_joints = 0;
  long broken_by_mode[3] = {0, 0, 0};  // tension, shear, mixed
  long fragments = -1;                 // discrete elements now (−1: not counted)
  long kinetic_damping_stops = -1;     // steps that stopped every free node (−1: not kinetic)
  // Model::gid_offset and the largest node, tet and joint gid held (−1: none): what the run's
  // gids were (a run with parallel.gid_offset shows them above it).
  std::int64_t gid_offset = 0, node_gid_max = -1, tet_gid_max = -1, joint_gid_max = -1;
  // Decomposition (N ranks): imbalance = max/mean owned cost, halo and migration sizes.
  bool parallel = false;
  std::string start;  // "distributed" (no rank held the whole model) or "whole_model"
  double imbalance = 1.0, max_imbalance = 1.0;
  long redistributions = 0, rebalances = 0, migrated_elements = 0;
  long halo_elements_max = 0, ghost_nodes_max = 0, ghost_nodes_mean = 0, neighbours_max = 0;
  long active_elements_max = 0;  // tets a rank computes internal forces for (owned + halo)
  long exchanged_ghosts_max = 0, exchanged_ghosts_mean = 0;  // ghost nodes the step exchanges
  MigrationReport migration;           // tet copies moved, re-partitions on measured cost
  double communication_seconds = 0.0;  // halo exchange + redistribution + reductions (rank 0)
  // Peak resident set size per rank (KiB, largest and mean over ranks): start-up (scene, model,
  // distribution) and the step loop after it (counted afresh once start-up memory is freed).
  long startup_peak_rss_kib_max = 0, startup_peak_rss_kib_mean = 0;
  long run_peak_rss_kib_max = 0, run_peak_rss_kib_mean = 0;
};

}  // namespace fdem
