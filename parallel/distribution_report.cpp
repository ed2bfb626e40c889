// What a distribution reports and what the ranks measure together (parallel/distribution.hpp):
// the migration's time split, the cycle's report (tets, halos, ghosts, neighbours, traffic;
// min / max / sum over the ranks), and the model's global state hash and fragment count.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/state_hash.hpp"
#include "core/types.hpp"
#include "parallel/distributed_pieces.hpp"
#include "parallel/distribution.hpp"

namespace fdem {

void Distribution::account_last_cycle(double seconds) {
  if (last_cycle_seconds_ < 0.0) return;  // no cycle since the start, or accounted already
  if (last_cycle_repartitioned_) {
    report_.migration.last_repartition_seconds = seconds;
    report_.migration.repartition_seconds += seconds;
  } else {
    report_.migration.incremental_seconds += seconds;
  }
  last_cycle_seconds_ = -1.0;
}

void Distribution::close_report() {
  const double last = comm_.max(std::max(last_cycle_seconds_, 0.0));
  account_last_cycle(last);
}

void Distribution::update_report(const Model& model, bool count_traffic) {
  const long owned = model.tets.n_owned;
  const long halo = model.tets.size() - model.tets.n_owned;
  const long ghosts = model.nodes.size() - model.nodes.n_owned;
  const long neighbours = static_cast<long>(neighbours_.size());
  long exchanged = 0;  // ghosts the step's exchange brings
  for (const Neighbour& nb : neighbours_) exchanged += static_cast<long>(nb.receive.size());
  // Minima as maxima of the negated values: one max-reduction and one sum.
  std::vector<std::int64_t> high = {owned,     halo,   ghosts, neighbours,
                                    exchanged, -owned, -halo,  -ghosts},
                            sum = {halo,
                                   ghosts,
                                   cycle_traffic_.sent_tets,
                                   cycle_traffic_.dropped_tets,
                                   cycle_traffic_.sent_bytes,
                                   exchanged};
  comm_.max_in_place(high);
  comm_.sum_in_place(sum);
  const std::int64_t low[3] = {-high[5], -high[6], -high[7]};
  report_.owned_tets_min = low[0];
  report_.owned_tets_max = high[0];
  report_.halo_tets_min = low[1];
  report_.halo_tets_max = high[1];
  report_.halo_tets_sum = sum[0];
  report_.ghost_nodes_min = low[2];
  report_.ghost_nodes_max = high[2];
  report_.ghost_nodes_sum = sum[1];
  report_.neighbours_max = high[3];
  report_.exchanged_ghosts_max = high[4];
  report_.exchanged_ghosts_sum = sum[5];
  if (count_traffic) {
    report_.last_sent_tets = sum[2];
    report_.last_dropped_tets = sum[3];
    report_.last_sent_bytes = sum[4];
    report_.migration.sent_tets += sum[2];
    report_.migration.dropped_tets += sum[3];
    report_.migration.sent_bytes += sum[4];
  }
  release(cycle_traffic_);
}

std::uint64_t global_state_hash(const Model& model, const Communicator& comm) {
  // Unsigned: the sum wraps modulo 2^64, like the local one.
  return comm.sum(state_hash(model.nodes, model.gid_offset));
}

std::uint64_t global_reference_hash(const Model& model, const Communicator& comm) {
  return comm.sum(reference_hash(model.nodes, model.gid_offset));
}

std::int64_t global_fragment_count(const Model& model, const Communicator& comm) {
  const TetArrays& tets = model.tets;
  const JointArrays& joints = model.joints;
  std::int64_t joint_count = 0;
  for (LocalIndex j = 0; j < joints.size(); ++j) joint_count += tets.is_owned(joints.tets[2 * j]);
  // Without joints the pieces at t = 0 are the components, as on one rank.
  if (comm.sum(joint_count) == 0) return static_cast<std::int64_t>(model.pieces.size());
  // Components of a distributed union-find (the one that finds the pieces of a model file) over
  // node rows (gid − offset): each owned tet joins its corners, and each intact joint owned by its
  // tet A joins a node of A to a node of B, given as the degenerate element (a, b, b, b).
  std::vector<std::int64_t> elements;
  elements.reserve(4 * static_cast<std::size_t>(tets.n_owned + joint_count));
  const auto row = [&](LocalIndex node) { return model.nodes.gid[node] - model.gid_offset; };
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    if (!tets.is_owned(t)) continue;
    for (int c = 0; c < 4; ++c) elements.push_back(row(tets.nodes[4 * t + c]));
  }
  for (LocalIndex j = 0; j < joints.size(); ++j) {
    if (!tets.is_owned(joints.tets[2 * j]) || joints.broken[j]) continue;
    const std::int64_t a = row(joints.nodes[6 * j]), b = row(joints.nodes[6 * j + 3]);
    elements.insert(elements.end(), {a, b, b, b});
  }
  const std::int64_t n_nodes = comm.sum(static_cast<std::int64_t>(model.nodes.n_owned));
  const std::int64_t first =
      comm.sum_over_lower_ranks(static_cast<std::int64_t>(elements.size() / 4));
  std::int32_t fragments = 0;
  distributed_pieces(elements, n_nodes, first, comm, &fragments);
  return fragments;
}

}  // namespace fdem
