// The distributed model: which rank owns which tet, the halo each rank holds, migration of tets
// with everything that travels with them, and the per-step ghost exchange (docs/parallel.md).
//
// Owner computes.  A tet has one owning rank; a node's owner is the owner of the lowest-gid tet
// that holds it.  A rank holds every tet whose box comes within a margin of the box of the tets it
// owns (margin = 2 × the largest tet extent + 2 × the contact buffer), which covers every tet that
// shares a node with an owned node, every contact partner such a tet can meet before the next
// detection, and every joint between them; it computes the forces of the tets that touch a node it
// owns (`TetArrays::active`), adds them in ascending gid, and so sums every owned node's force in
// the order one rank does.  Only positions and velocities of ghost nodes travel each step
// (without contact, only of the ghosts the step reads).
//
// Redistribution happens at contact-detection cycles: the owned cost (tets, joints, contact
// pairs) is compared across ranks; Zoltan re-partitions when the imbalance exceeds a threshold and
// the measured gain pays for it, and every owner sends each of its tets — with its nodes, the
// joints whose first tet it is, the stages' records of its pairs and its contact state — to the new
// owner and to every rank whose margin box it meets.  A cycle without re-partition is incremental:
// only the copies a rank does not hold yet travel, and copies no longer needed are dropped.  Every
// exchange is neighbour-only (Communicator::exchange_sparse).
#pragma once

#include <cstdint>
#include <initializer_list>
#include <utility>
#include <vector>

#include "core/migration_report.hpp"
#include "core/model.hpp"
#include "core/travelling_state.hpp"
#include "parallel/communicator.hpp"
#include "parallel/distributed_build.hpp"
#include "parallel/zoltan_partition.hpp"

namespace fdem {

struct DistributionSettings {
  double rebalance_threshold = 1.10;  // re-partition when max/mean owned cost exceeds this
  double joint_cost = 1.0;            // cost of an intact joint
  GeometricMethod partitioner = GeometricMethod::rib;  // the re-partition at detection cycles
  // Test mode: every re-partition deals the tets to ranks at random (by gid and cycle).
  bool random_parts = false;
  // Cycles without re-partition send only the copies a rank does not hold yet (false: every
  // copy at every cycle).
  bool incremental = true;
  // Re-partition only when the predicted gain (the busiest rank's measured busy seconds over
  // the last interval above the mean) exceeds the measured seconds of the last re-partition
  // cycle; the first re-partition, before any was measured, goes by the cost weights alone.
  bool measured_repartition = true;
};

// What the last (re)distribution did, the same on every rank.
struct DistributionReport {
  long cycles = 0;                // redistributions so far (the first is the initial one)
  long rebalances = 0;            // of which re-partitioned
  long migrated_tets = 0;         // tets that changed owner, summed over all cycles
  double imbalance = 1.0;         // max/mean owned cost after the last cycle
  double imbalance_before = 1.0;  // ... before its re-partition
  double max_imbalance = 1.0;     // largest imbalance seen at a cycle (before re-partition)
  long owned_tets_min = 0, owned_tets_max = 0;
  long halo_tets_min = 0, halo_tets_max = 0, halo_tets_sum = 0;
  long ghost_nodes_min = 0, ghost_nodes_max = 0, ghost_nodes_sum = 0;
  long neighbours_max = 0;  // ranks a rank exchanges ghosts with
  // Ghost nodes the step's exchange brings (without contact only those the forces read).
  long exchanged_ghosts_max = 0, exchanged_ghosts_sum = 0;
  MigrationReport migration;  // traffic and measured cost, summed over the cycles
  long last_sent_tets = 0, last_dropped_tets = 0, last_sent_bytes = 0;  // of the last cycle
};

class Distribution {
 public:
  // Collective.  Every rank passes the same whole model (built from the scene) and the contact
  // buffer (m, 0 without contact).  Partitions it with METIS on the element graph (rank 0,
  // broadcast; edges: shared faces, intact joints, `neighbours`), and returns through
  // `local`/`local_state` this rank's part with its halo. `neighbours`: pairs of tets (indices of
  // `global`) to keep together besides the mesh and joints — the contact candidates at the start,
  // so that blocks resting on each other share a rank.
  Distribution(const Communicator& comm, DistributionSettings settings, const Model& global,
               const TravellingState& global_state, double buffer,
               const std::vector<std::pair<LocalIndex, LocalIndex>>& neighbours, Model& local,
               TravellingState& local_state);

  // Collective, distributed start: every rank passes its block of the model
  // (build_distributed_model) and the contact buffer.  The blocks — a Morton space-filling curve
  // over the tet centroids cut into equal parts — are the initial partition; each rank receives
  // the halo its tets need from the ranks that own it, and no rank ever holds the whole model.
  // Joints travel with their tet A; `local_state.tet_joint_state` gets each tet's joint state
  // (bonded anywhere: pass it to the contact stage, whose bonds see only the joints held here).
  Distribution(const Communicator& comm, DistributionSettings settings, DistributedModel start,
               double buffer, Model& local, TravellingState& local_state);

  // Collective, at a contact-detection cycle: measures the owned cost (a tet costs 1; plus
  // `contact_cost`: the cost of the contact pairs whose first tet it is, in the same unit, or
  // empty), re-partitions when the
  // imbalance exceeds the threshold, migrates, and rebuilds the halo and the ghost exchange.
  // `busy_seconds`: this rank's compute time since the last cycle (re-partitioning on measured
  // cost, DistributionSettings::measured_repartition).
  void redistribute(Model& model, TravellingState& state, const std::vector<double>& contact_cost,
                    double busy_seconds);
  // Collective, before the report is read at the end of a run: accounts the last cycle's time.
  void close_report();

  // Split-phase ghost exchange of positions and velocities: start() after integration posts the
  // sends and receives, finish() completes them and writes the ghost entries.
  void start_halo_exchange(const NodeArrays& nodes);
  void finish_halo_exchange(NodeArrays& nodes);

  const DistributionReport& report() const { return report_; }
  // Per local node: the rank that owns it (xdmf frames ask ghost nodes' owners for their rows).
  const std::vector<std::int32_t>& node_owners() const { return node_owner_; }
  // For each owned tet, the other ranks that hold a copy, as (gid, rank) sorted: what an
  // incremental cycle sends against.
  const std::vector<std::pair<GlobalId, std::int32_t>>& copies_elsewhere() const {
    return held_by_;
  }
  // Collective, neighbour-only (Communicator::exchange_sparse): record i (`record_bytes` bytes
  // at records[i × record_bytes]) concerns tet `tets[i]`, owned here; it goes to every other rank
  // that holds a copy of that tet.  Returns the records that arrived, in source rank order.
  // What the step tells about a tet (a broken joint) reaches the ranks that hold it, and no one
  // else.
  std::vector<char> send_to_holders(const std::vector<GlobalId>& tets,
                                    const std::vector<char>& records,
                                    std::size_t record_bytes) const;

 private:
  // Tets per buffer of this rank's own rows in a migration (~1 kB of rows per tet of a jointed
  // body, a few per other tet): the buffers are freed one by one as they are parsed.
  static constexpr std::size_t own_chunk_tets = 4096;
  struct Neighbour {
    int rank = 0;
    std::vector<LocalIndex> send, receive;  // local node indices
    std::vector<double> send_buffer, receive_buffer;
  };
  // Sends the owned tets where destinations() says, frees `model`'s mesh arrays and `state` once
  // packed, and assembles what arrives into `out` (which may be `model`).
  // `start_joints`, `start_reach` (distributed start): the block's joints by gid and each tet's
  // reach over the whole model (DistributedModel).
  void migrate(Model& model, TravellingState& state, Model& out, TravellingState& out_state,
               const std::vector<StartJoint>* start_joints = nullptr,
               const std::vector<double>* start_reach = nullptr);
  // The start (parallel/distribution_start.cpp) of a scene without joints: every local tet is
  // owned here, so only halo copies travel, and they are appended to `model` in place (gid order
  // kept): no second copy of the model is ever made.
  void append_halo(Model& model, TravellingState& state, const std::vector<double>* start_reach);
  // Packs lists[p] for the other ranks into `send` (counts in 8-byte words) and lists[me] into
  // `own` when given, as buffers of at most own_chunk_tets tets each (parse_rows frees each once
  // read, so this rank's own rows and their parsed copy are not held whole at once);
  // exchange_rows sends them (freeing `send`) and returns what arrived.
  // Returns the tet copies packed for other ranks.  `both_sides`: each tet carries every joint
  // of which it is a side (RowPacker).
  long pack_rows(const Model& model, const TravellingState& state,
                 const std::vector<std::vector<LocalIndex>>& lists, std::vector<char>& send,
                 std::vector<std::size_t>& send_counts, std::vector<std::vector<char>>* own,
                 const std::vector<StartJoint>* start_joints = nullptr,
                 bool both_sides = false) const;
  std::vector<char> exchange_rows(std::vector<char>& send,
                                  const std::vector<std::size_t>& send_counts) const;
  // A cycle without re-partition: owners and active tets stay, so every copy a rank holds is
  // current (ghost positions from the completed halo exchange, the stages' state of what it
  // computes).  Each owner sends only the copies a rank does not hold yet (`held_by_`) and tells
  // the ranks that no longer need one to drop it; each rank rebuilds from what it kept and what
  // arrived.  Bytes on the wire ∝ the tets that entered or left a halo.
  void migrate_incremental(Model& model, TravellingState& state);
  // Frees `source`'s mesh arrays and `source_state` (the rows hold what travels), sends the rows,
  // and builds `out` (which may be `source`) from what arrived and this rank's `own` rows.
  void move_rows(Model& source, TravellingState& source_state, std::vector<char>& send,
                 const std::vector<std::size_t>& send_counts, std::vector<std::vector<char>>& own,
                 Model& out, TravellingState& out_state);
  // After a full migration: every rank tells the owners of the tets it holds (not owned) that it
  // holds them, so that the next incremental cycle knows where copies are.
  void record_holders(const Model& model);
  // Builds `model` from packed rows; empties each buffer once parsed.
  void assemble(const std::vector<std::vector<char>*>& buffers, Model& model,
                TravellingState& state);
  void build_exchange(const Model& model);
  void start_exchange(std::vector<Neighbour>& plan, const NodeArrays& nodes);
  void finish_exchange(const std::vector<Neighbour>& plan, NodeArrays& nodes);
  // Blocking exchange of every ghost's position and velocity (when the step's is trimmed).
  void refresh_all_ghosts(NodeArrays& nodes);
  // After a re-partition: the new owner of each node of an owned tet (the new owner of its first
  // tet), through a directory of tet owners keyed by gid.
  void update_node_owners(const Model& model);
  // Per rank, the local tets to send it: each sending tet to its owner and to every rank that
  // claimed a cell its box grown by 2.5 buffers (+ the widest joint gap) touches; a rank claims
  // the cells within reach of each tet it will own.  `whole`: every rank holds the whole model
  // (the start) and all tets send, without exchanging claims; else the owned tets send.
  // `start_reach`: a lower bound of each local tet's reach (the distributed start's blocks do not
  // hold their neighbours in other blocks).  `x_also`: other positions per local node (those of
  // the last contact detection) that each tet's box must span as well.
  std::vector<std::vector<LocalIndex>> destinations(
      const Model& model, bool whole, const std::vector<double>* start_reach = nullptr,
      const std::vector<double>* x_also = nullptr) const;
  // The slowest rank's seconds of the last cycle, once known (at the next cycle or the end).
  void account_last_cycle(double seconds);
  // `count_traffic`: add this cycle's migration traffic (not the initial distribution's).
  void update_report(const Model& model, bool count_traffic);

  Communicator comm_;
  DistributionSettings settings_;
  double buffer_ = 0.0;
  // Per local tet: its owner (after a re-partition, its new one).  Per local node: the smallest
  // tet gid that uses it (fixed for the run) and that tet's owner, which owns the node.  Local
  // only: no rank keeps a table of the whole model.
  std::vector<std::int32_t> tet_owner_;
  std::vector<std::int32_t> node_owner_;
  std::vector<GlobalId> node_first_tet_;
  GlobalId n_tets_ = 0;      // tets of the whole model
  GlobalId gid_offset_ = 0;  // Model::gid_offset: tet gids are gid_offset_ + 0..n_tets_−1
  // For each owned tet, the other ranks that hold a copy: (gid, rank), sorted.
  std::vector<std::pair<GlobalId, std::int32_t>> held_by_;
  // The step's ghost exchange (without contact: only the ghosts the forces and the stable-step
  // guard read, `trimmed_`), and every ghost (filled when trimmed), brought up to date before a
  // redistribution.
  std::vector<Neighbour> neighbours_, all_ghosts_;
  bool trimmed_ = false;
  std::vector<MPI_Request> requests_;
  DistributionReport report_;
  struct Traffic {
    long sent_tets = 0, dropped_tets = 0, sent_bytes = 0;
  } cycle_traffic_;                   // this rank's, of the cycle under way
  double last_cycle_seconds_ = -1.0;  // this rank's, of the last cycle (−1: accounted)
  bool last_cycle_repartitioned_ = false;
  bool has_joint_state_ = false;    // the scene has joints: tets carry their joint state
  bool has_contact_faces_ = false;  // corner contact: tets carry TetArrays::contact_faces
};

// Collective: state_hash (core/state_hash.hpp) of the owned nodes of all ranks, the value one rank
// holding every node computes (one integer sum-reduction).
std::uint64_t global_state_hash(const Model& model, const Communicator& comm);
// Collective: reference_hash of the owned nodes of all ranks.
std::uint64_t global_reference_hash(const Model& model, const Communicator& comm);

// Collective: count_fragments (core/model.hpp) of the whole model — connected components of tets
// linked by a shared node or an intact joint — from each rank's owned tets and joints.
std::int64_t global_fragment_count(const Model& model, const Communicator& comm);

}  // namespace fdem
