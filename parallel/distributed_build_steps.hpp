// The steps of the distributed start-up (parallel/distributed_build.hpp) and the records they pass
// between ranks: internal to parallel/, shared by distributed_build.cpp (the driver of the
// steps) and distributed_build_steps.cpp (steps 1-4).
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "parallel/distributed_build.hpp"

namespace fdem::distributed_build_steps {

// A tet on its way to its block: sort key, origin, corners as whole-model mesh node numbers
// (body node base + number in the body mesh) and corner reference positions.
struct TetRecord {
  std::uint64_t key;
  std::int32_t body, piece;  // piece: model piece index
  std::int64_t mesh_tet;     // index in its body's mesh
  std::int64_t node[4];
  double x[12];  // m
};

// A record without its positions (48 of 152 bytes), once the nodes hold them.
struct TetLinks {
  std::int32_t body, piece;
  std::int64_t mesh_tet;
  std::int64_t node[4];
};

// build_model's order: Morton key, ties by input order (body, then mesh tet).
struct SortKey {
  std::uint64_t key;
  std::int64_t body, mesh_tet;
};
inline bool operator<(const SortKey& a, const SortKey& b) {
  if (a.key != b.key) return a.key < b.key;
  if (a.body != b.body) return a.body < b.body;
  return a.mesh_tet < b.mesh_tet;
}
inline SortKey sort_key(const TetRecord& r) {
  return {r.key, r.body, r.mesh_tet};
}

// Keys of the model's nodes before they are numbered: the node of a mesh node (node base of the
// body + mesh node number: every corner at that mesh node shares it), except in a `joints: all`
// body, where every tet corner is a node of its own (split base of the body + 4 × mesh tet +
// corner), as build_model splits them.  Split keys follow all mesh node keys.
struct NodeKeys {
  std::vector<std::int64_t> split_base;  // per body; −1: the body's nodes are not split
  std::int64_t split_start = 0;          // the first split key
  template <class Record>                // TetRecord or TetLinks
  std::int64_t key(const Record& r, int c) const {
    const std::int64_t base = split_base[static_cast<std::size_t>(r.body)];
    return base < 0 ? r.node[c] : base + 4 * r.mesh_tet + c;
  }
  template <class Record>
  bool split(const Record& r) const {
    return split_base[static_cast<std::size_t>(r.body)] >= 0;
  }
};

// A use of a node (by its key, NodeKeys) by a tet corner: use = 4 × tet index + corner, the tet
// index being gid − gid_offset (first use = smallest; 4 × gid could overflow for large offsets).
struct NodeUse {
  std::int64_t mesh_node, use;
  double x[3];
};
// A node's (key's) model gid and its first tet.
struct NodeNumber {
  std::int64_t mesh_node;
  GlobalId gid, first_tet;
};
struct MassPart {
  GlobalId node, tet;
  double mass;    // kg
  double extent;  // m: the tet's largest box side
};
struct NodeMass {
  GlobalId node;
  double mass;    // kg
  double extent;  // m: the largest extent among the node's tets
};

// Rank holding global position g when [block[r], block[r+1]) is rank r's.
int block_owner(const std::vector<GlobalId>& block, GlobalId g);

// Directory rank of a node: the rank whose stretch of the Morton curve (its block of tets, sorted
// by key) holds the key of the node's position.  Every user of a node computes the same rank, and
// most nodes are their users' own rank: only nodes along the blocks' borders travel.
class NodeDirectory {
 public:
  NodeDirectory(const std::vector<TetRecord>& block, const Vec3& lo, const Vec3& hi,
                const Communicator& comm)
      : lo_(lo), hi_(hi) {
    const std::uint64_t none = std::numeric_limits<std::uint64_t>::max();
    const std::vector<std::uint64_t> first = comm.allgather(block.empty() ? none : block[0].key);
    for (int r = 0; r < comm.size(); ++r)
      if (first[r] != none) {
        first_key_.push_back(first[r]);
        rank_.push_back(r);
      }
  }
  int rank_of(const double x[3]) const {
    const std::uint64_t key = morton_key(Vec3(x[0], x[1], x[2]), lo_, hi_);
    const auto it = std::upper_bound(first_key_.begin(), first_key_.end(), key);
    return rank_[it == first_key_.begin() ? 0
                                          : static_cast<std::size_t>(it - first_key_.begin()) - 1];
  }

 private:
  Vec3 lo_, hi_;
  std::vector<std::uint64_t> first_key_;  // of each rank that holds tets, ascending
  std::vector<int> rank_;
};

// Sample sort of the records of all ranks, cut into the blocks: rank r ends with global positions
// [block[r], block[r+1]) in order (positions count from block[0], the gid offset).
std::vector<TetRecord> sort_into_blocks(std::vector<TetRecord> local,
                                        const std::vector<GlobalId>& block,
                                        const Communicator& comm);

// Steps 1–2: this rank's chunks generated, shapes checked, keys given.
std::vector<TetRecord> generate_records(const Scene& scene, const std::vector<BodyChunks>& chunks,
                                        const std::vector<std::int64_t>& node_base,
                                        const std::vector<std::int32_t>& piece_base,
                                        std::int64_t block_tets, const Communicator& comm,
                                        Vec3* node_lo, Vec3* node_hi);

// Step 4: node gids by first use.  Returns the numbers of the nodes of the local tets, by key.
// Split nodes (one tet's own) are numbered here without a directory.  Tet and node gids are
// gid_offset + their index (block[0] = gid_offset).
std::vector<NodeNumber> number_nodes(const std::vector<TetRecord>& tets, GlobalId first_tet,
                                     const std::vector<GlobalId>& block, const NodeKeys& keys,
                                     const NodeDirectory& directory, const Communicator& comm,
                                     GlobalId* n_nodes);

}  // namespace fdem::distributed_build_steps
