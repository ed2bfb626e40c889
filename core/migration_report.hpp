// What the migrations and re-partitions of an N-rank run moved and cost: filled by the
// distribution (parallel/distribution.hpp), reported in summary.json → decomposition.  The same
// on every rank.
#pragma once

namespace fdem {

struct MigrationReport {
  // Tet copies sent (a tet sent to its owner and two halo ranks counts 3), copies dropped by a
  // rank that no longer needs them and bytes of rows sent, summed over ranks and over the cycles
  // after the first.  Incremental cycles (no re-partition) send only the copies a rank does not
  // hold yet.
  long incremental_cycles = 0;
  long sent_tets = 0, dropped_tets = 0, sent_bytes = 0;
  // Re-partitioning on measured cost: the busiest rank's busy seconds over the mean at the last
  // cycle; seconds of the cycles (the slowest rank's), re-partitioning and incremental; the
  // last re-partition's (−1: none timed yet); the predicted gains of the re-partitions made; the
  // cycles whose weights called for a re-partition that the measured gain did not justify.
  double measured_imbalance = 1.0;
  double repartition_seconds = 0.0, incremental_seconds = 0.0;
  double last_repartition_seconds = -1.0;
  double predicted_gain_seconds = 0.0;
  long repartitions_declined = 0;
};

}  // namespace fdem
