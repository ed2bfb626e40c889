#include "parallel/distributed_build.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <numeric>

#include "core/error.hpp"
#include "core/joint_placement.hpp"
#include "core/tet_kernels.hpp"
#include "parallel/distributed_joints.hpp"
#include "parallel/piece_directory.hpp"

namespace fdem {

namespace {

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
bool operator<(const SortKey& a, const SortKey& b) {
  if (a.key != b.key) return a.key < b.key;
  if (a.body != b.body) return a.body < b.body;
  return a.mesh_tet < b.mesh_tet;
}
SortKey sort_key(const TetRecord& r) {
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

// Rank holding global position g when [block[r], block[r+1]) is rank r's.
int block_owner(const std::vector<GlobalId>& block, GlobalId g) {
  return static_cast<int>(std::upper_bound(block.begin(), block.end(), g) - block.begin()) - 1;
}

// Sample sort of the records of all ranks, cut into the blocks: rank r ends with global positions
// [block[r], block[r+1]) in order (positions count from block[0], the gid offset).
std::vector<TetRecord> sort_into_blocks(std::vector<TetRecord> local,
                                        const std::vector<GlobalId>& block,
                                        const Communicator& comm) {
  const auto less = [](const TetRecord& a, const TetRecord& b) {
    return sort_key(a) < sort_key(b);
  };
  std::sort(local.begin(), local.end(), less);
  const int ranks = comm.size();
  if (ranks == 1) return local;
  // Splitters from regular samples (32 per rank): O(P) keys on every rank.
  constexpr std::size_t samples_per_rank = 32;
  std::vector<SortKey> samples;
  const std::size_t n = local.size(), s = std::min(n, samples_per_rank);
  for (std::size_t i = 0; i < s; ++i) samples.push_back(sort_key(local[(2 * i + 1) * n / (2 * s)]));
  std::vector<SortKey> all = comm.allgatherv(samples);
  std::sort(all.begin(), all.end());
  std::vector<SortKey> splitters;
  for (int r = 1; r < ranks && !all.empty(); ++r)
    splitters.push_back(all[static_cast<std::size_t>(r) * all.size() / ranks]);
  // Sorted, so each bucket is a contiguous range: sent straight from `local` (no copy).
  std::vector<std::size_t> counts(static_cast<std::size_t>(ranks), 0);
  for (const TetRecord& r : local)
    ++counts[static_cast<std::size_t>(
        std::upper_bound(splitters.begin(), splitters.end(), sort_key(r)) - splitters.begin())];
  std::vector<TetRecord>& bucket = local;  // most records stay: sorted in place
  comm.exchange_grouped_in_place(bucket, counts);
  std::sort(bucket.begin(), bucket.end(), less);
  // Buckets are in global order by rank: each record's position, and so its block, follows.
  const std::vector<std::int64_t> sizes = comm.allgather(static_cast<std::int64_t>(bucket.size()));
  const GlobalId first =
      block.front() + std::accumulate(sizes.begin(), sizes.begin() + comm.rank(), std::int64_t{0});
  counts.assign(static_cast<std::size_t>(ranks), 0);
  for (std::size_t i = 0; i < bucket.size(); ++i)
    ++counts[static_cast<std::size_t>(block_owner(block, first + static_cast<GlobalId>(i)))];
  comm.exchange_grouped_in_place(bucket, counts);  // from lower ranks first, each sorted: in order
  return std::move(bucket);
}

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

// Steps 1–2: this rank's chunks generated, shapes checked, keys given.
std::vector<TetRecord> generate_records(const Scene& scene, const std::vector<BodyChunks>& chunks,
                                        const std::vector<std::int64_t>& node_base,
                                        const std::vector<std::int32_t>& piece_base,
                                        std::int64_t block_tets, const Communicator& comm,
                                        Vec3* node_lo, Vec3* node_hi) {
  std::int64_t total = 0, dealt = 0;
  for (const BodyChunks& body : chunks)
    for (std::int64_t n : body.chunk_tets) {
      total += n;
      dealt += body.chunk_rank.empty() ? n : 0;
    }
  if (total == 0) throw InputError(scene.source_path + ": the scene has no tetrahedra");
  // Chunks are dealt along a Morton curve of their centres, in equal shares of tets, so that most
  // tets are generated on the rank whose block (a stretch of the same kind of curve) they join.
  // Chunks placed on their ranks already (chunk_rank) are not dealt.
  struct ChunkRef {
    std::uint64_t key;
    std::int32_t body;
    std::int64_t chunk;
  };
  std::vector<ChunkRef> deal, placed;
  Vec3 centre_lo = Vec3::Constant(1e300), centre_hi = Vec3::Constant(-1e300);
  for (const BodyChunks& body : chunks) {  // ≈ the box of all nodes, as the tets' keys use
    centre_lo = centre_lo.cwiseMin(body.lo);
    centre_hi = centre_hi.cwiseMax(body.hi);
  }
  for (std::size_t b = 0; b < chunks.size(); ++b)
    for (std::size_t c = 0; c < chunks[b].chunk_tets.size(); ++c) {
      const ChunkRef ref{morton_key(chunks[b].chunk_centre[c], centre_lo, centre_hi),
                         static_cast<std::int32_t>(b), static_cast<std::int64_t>(c)};
      if (chunks[b].chunk_rank.empty())
        deal.push_back(ref);
      else if (chunks[b].chunk_rank[c] == comm.rank())
        placed.push_back(ref);
    }
  std::stable_sort(deal.begin(), deal.end(),
                   [](const ChunkRef& a, const ChunkRef& b) { return a.key < b.key; });
  std::vector<TetRecord> records;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  const auto add_chunk = [&](const ChunkRef& ref) {
    const std::size_t b = static_cast<std::size_t>(ref.body);
    const MeshChunk chunk = chunks[b].generate(ref.chunk);
    const std::vector<double>& coords = chunk.mesh.coords;
    for (std::size_t n = 0; n < coords.size() / 3; ++n) {
      lo = lo.cwiseMin(vec3_at(coords.data(), static_cast<LocalIndex>(n)));
      hi = hi.cwiseMax(vec3_at(coords.data(), static_cast<LocalIndex>(n)));
    }
    for (std::size_t t = 0; t < chunk.mesh.tets.size() / 4; ++t) {
      TetRecord r{};
      r.body = static_cast<std::int32_t>(b);
      r.piece = piece_base[b] + (chunk.tet_piece.empty() ? chunk.piece : chunk.tet_piece[t]);
      r.mesh_tet = chunk.tet_id[t];
      Vec3 X[4];
      for (int k = 0; k < 4; ++k) {
        const LocalIndex n = chunk.mesh.tets[4 * t + k];
        r.node[k] = node_base[b] + chunk.node_id[static_cast<std::size_t>(n)];
        X[k] = vec3_at(coords.data(), n);
        for (int d = 0; d < 3; ++d) r.x[3 * k + d] = X[k][d];
      }
      // Named as the serial builder names it: the file's element tag, or its number + 1.
      check_tet_shape(X, scene.bodies[b].name,
                      chunk.mesh.source.empty() ? chunks[b].source : chunk.mesh.source,
                      chunk.mesh.source_tags.empty() ? r.mesh_tet + 1 : chunk.mesh.source_tags[t]);
      records.push_back(r);
    }
  };
  const auto tets_of = [&](const ChunkRef& ref) {
    return chunks[static_cast<std::size_t>(ref.body)]
        .chunk_tets[static_cast<std::size_t>(ref.chunk)];
  };
  std::vector<ChunkRef> mine = placed;
  std::int64_t before = 0;  // tets of the chunks dealt before this one
  for (const ChunkRef& ref : deal) {
    // Each chunk goes to the rank whose share of the tets it starts in.
    if (static_cast<int>(mul_div(before, comm.size(), dealt)) == comm.rank()) mine.push_back(ref);
    before += tets_of(ref);
  }
  // The records are the largest array of the start-up: reserved once (growing by push_back would
  // hold up to twice their size, and both copies while it reallocates), with room for the
  // rank's block and the sample sort's uneven buckets, so that they are sorted in place.
  std::int64_t my_tets = 0;
  for (const ChunkRef& ref : mine) my_tets += tets_of(ref);
  records.reserve(static_cast<std::size_t>(std::max(my_tets, block_tets) + block_tets / 16));
  comm.run_collectively([&] {
    for (const ChunkRef& ref : mine) add_chunk(ref);
  });
  std::vector<double> low(lo.data(), lo.data() + 3), high(hi.data(), hi.data() + 3);
  comm.min_in_place(low);
  comm.max_in_place(high);
  lo = Vec3(low[0], low[1], low[2]);
  hi = Vec3(high[0], high[1], high[2]);
  for (TetRecord& r : records) {
    Vec3 c = Vec3::Zero();
    for (int k = 0; k < 4; ++k) c += Vec3(r.x[3 * k], r.x[3 * k + 1], r.x[3 * k + 2]);
    r.key = morton_key(0.25 * c, lo, hi);
  }
  *node_lo = lo;
  *node_hi = hi;
  return records;
}

// Step 4: node gids by first use.  Returns the numbers of the nodes of the local tets, by key.
// Split nodes (one tet's own) are numbered here without a directory.  Tet and node gids are
// gid_offset + their index (block[0] = gid_offset).
std::vector<NodeNumber> number_nodes(const std::vector<TetRecord>& tets, GlobalId first_tet,
                                     const std::vector<GlobalId>& block, const NodeKeys& keys,
                                     const NodeDirectory& directory, const Communicator& comm,
                                     GlobalId* n_nodes) {
  const int ranks = comm.size();
  const GlobalId gid_offset = block.front();
  const std::int64_t first_index = first_tet - gid_offset;
  const auto tet_of_use = [&](std::int64_t use) { return gid_offset + use / 4; };
  // This rank's first use of each node it uses (one message per node, not per corner).
  std::vector<std::pair<std::int64_t, std::int64_t>> corner;  // (node key, use)
  std::vector<NodeUse> split;  // uses of split nodes: their first and only
  corner.reserve(4 * tets.size());
  for (std::size_t t = 0; t < tets.size(); ++t)
    for (int c = 0; c < 4; ++c) {
      const std::int64_t use = 4 * (first_index + static_cast<std::int64_t>(t)) + c;
      if (!keys.split(tets[t])) {
        corner.emplace_back(tets[t].node[c], use);
        continue;
      }
      NodeUse u{keys.key(tets[t], c), use, {}};
      std::copy_n(&tets[t].x[3 * c], 3, u.x);
      split.push_back(u);
    }
  std::sort(corner.begin(), corner.end());
  std::vector<std::vector<NodeUse>> uses(static_cast<std::size_t>(ranks));
  for (std::size_t i = 0; i < corner.size(); ++i) {
    if (i > 0 && corner[i].first == corner[i - 1].first) continue;
    NodeUse u{corner[i].first, corner[i].second, {}};
    const TetRecord& r = tets[static_cast<std::size_t>(corner[i].second / 4 - first_index)];
    std::copy_n(&r.x[3 * (corner[i].second % 4)], 3, u.x);
    uses[static_cast<std::size_t>(directory.rank_of(u.x))].push_back(u);
  }
  corner.clear();
  corner.shrink_to_fit();
  // Directory: the first use of each node, and who asked.
  std::vector<int> asker;
  std::vector<NodeUse> seen = comm.exchange(uses, &asker);
  uses.assign(static_cast<std::size_t>(ranks), {});
  std::vector<std::size_t> order(seen.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return seen[a].mesh_node != seen[b].mesh_node ? seen[a].mesh_node < seen[b].mesh_node
                                                  : seen[a].use < seen[b].use;
  });
  std::vector<std::vector<NodeUse>> firsts(static_cast<std::size_t>(ranks));
  for (std::size_t i = 0; i < order.size(); ++i)
    if (i == 0 || seen[order[i]].mesh_node != seen[order[i - 1]].mesh_node)
      firsts[static_cast<std::size_t>(block_owner(block, tet_of_use(seen[order[i]].use)))]
          .push_back(seen[order[i]]);
  // First users' ranks number the nodes they own, in order of first use.
  std::vector<NodeUse> owned = comm.exchange(firsts);
  firsts.clear();
  owned.insert(owned.end(), split.begin(), split.end());
  split.clear();
  split.shrink_to_fit();
  std::sort(owned.begin(), owned.end(),
            [](const NodeUse& a, const NodeUse& b) { return a.use < b.use; });
  const std::vector<std::int64_t> counts = comm.allgather(static_cast<std::int64_t>(owned.size()));
  const GlobalId base =
      gid_offset + std::accumulate(counts.begin(), counts.begin() + comm.rank(), std::int64_t{0});
  *n_nodes = std::accumulate(counts.begin(), counts.end(), std::int64_t{0});
  std::vector<std::vector<NodeNumber>> numbers(static_cast<std::size_t>(ranks));
  std::vector<NodeNumber> split_numbers;
  for (std::size_t i = 0; i < owned.size(); ++i) {
    const NodeNumber number{owned[i].mesh_node, base + static_cast<GlobalId>(i),
                            tet_of_use(owned[i].use)};
    if (number.mesh_node >= keys.split_start)
      split_numbers.push_back(number);
    else
      numbers[static_cast<std::size_t>(directory.rank_of(owned[i].x))].push_back(number);
  }
  // Back to the directory, which answers every rank that used the node.
  std::vector<NodeNumber> known = comm.exchange(numbers);
  numbers.assign(static_cast<std::size_t>(ranks), {});
  std::sort(known.begin(), known.end(),
            [](const NodeNumber& a, const NodeNumber& b) { return a.mesh_node < b.mesh_node; });
  for (std::size_t i = 0; i < order.size(); ++i) {
    const NodeUse& u = seen[order[i]];
    const int to = asker[order[i]];  // each rank sent each of its nodes once
    const auto it =
        std::lower_bound(known.begin(), known.end(), u.mesh_node,
                         [](const NodeNumber& a, std::int64_t m) { return a.mesh_node < m; });
    FDEM_VERIFY(it != known.end() && it->mesh_node == u.mesh_node, "every node is numbered");
    numbers[static_cast<std::size_t>(to)].push_back(*it);
  }
  std::vector<NodeNumber> mine = comm.exchange(numbers);
  mine.insert(mine.end(), split_numbers.begin(), split_numbers.end());
  std::sort(mine.begin(), mine.end(),
            [](const NodeNumber& a, const NodeNumber& b) { return a.mesh_node < b.mesh_node; });
  return mine;
}

}  // namespace

DistributedModel build_distributed_model(const Scene& scene, const std::vector<BodyChunks>& chunks,
                                         const Communicator& comm) {
  FDEM_VERIFY(chunks.size() == scene.bodies.size(), "one chunk plan per body");
  const int ranks = comm.size(), me = comm.rank();
  DistributedModel out;
  Model& model = out.model;
  model = model_frame(scene);
  std::vector<std::int64_t> node_base(chunks.size() + 1, 0);
  std::vector<std::int32_t> piece_base(chunks.size() + 1, 0);
  std::vector<std::int64_t> body_tets(chunks.size(), 0);
  for (std::size_t b = 0; b < chunks.size(); ++b) {
    node_base[b + 1] = node_base[b] + chunks[b].n_nodes;
    piece_base[b + 1] = piece_base[b] + chunks[b].n_pieces;
    model.pieces.add_body(chunks[b].n_pieces);
    for (std::int64_t n : chunks[b].chunk_tets) body_tets[b] += n;
    out.n_tets += body_tets[b];
  }
  NodeKeys keys;
  keys.split_start = node_base.back();
  std::int64_t next_split = keys.split_start;
  for (std::size_t b = 0; b < chunks.size(); ++b) {
    const bool split = scene.bodies[b].joints == JointPlacement::all;
    keys.split_base.push_back(split ? next_split : -1);
    if (split) next_split += 4 * body_tets[b];
  }

  // Steps 1–3: records generated here, sorted into equal blocks of gids.
  Vec3 lo, hi;  // box of all nodes (m)
  std::vector<TetRecord> records = generate_records(
      scene, chunks, node_base, piece_base,
      mul_div(out.n_tets, me + 1, ranks) - mul_div(out.n_tets, me, ranks), comm, &lo, &hi);
  out.tet_block.resize(static_cast<std::size_t>(ranks) + 1);
  for (int r = 0; r <= ranks; ++r)
    out.tet_block[r] = model.gid_offset + mul_div(out.n_tets, r, ranks);
  records = sort_into_blocks(std::move(records), out.tet_block, comm);
  const GlobalId first_tet = out.tet_block[me];
  FDEM_VERIFY(static_cast<GlobalId>(records.size()) == out.tet_block[me + 1] - first_tet,
              "a rank receives its block of tets");

  // Step 4: node numbers; local nodes = owned (first used here) then the others, each by gid.
  const std::vector<NodeNumber> numbers =
      number_nodes(records, first_tet, out.tet_block, keys, NodeDirectory(records, lo, hi, comm),
                   comm, &out.n_nodes);
  const auto number_of = [&](std::int64_t mesh_node) -> const NodeNumber& {
    const auto it =
        std::lower_bound(numbers.begin(), numbers.end(), mesh_node,
                         [](const NodeNumber& a, std::int64_t m) { return a.mesh_node < m; });
    FDEM_VERIFY(it != numbers.end() && it->mesh_node == mesh_node, "a used node has a number");
    return *it;
  };
  struct LocalNode {
    GlobalId gid, first_tet;
    const double* x;
    std::int32_t piece;
  };
  // One entry per node used here (`numbers` holds each once, by mesh node): its position and
  // piece from the first corner that uses it.
  std::vector<LocalNode> local_nodes(numbers.size(), LocalNode{0, 0, nullptr, 0});
  for (const TetRecord& r : records)
    for (int c = 0; c < 4; ++c) {
      const NodeNumber& n = number_of(keys.key(r, c));
      LocalNode& l = local_nodes[static_cast<std::size_t>(&n - numbers.data())];
      if (!l.x) l = {n.gid, n.first_tet, &r.x[3 * c], r.piece};
    }
  for (const LocalNode& l : local_nodes) FDEM_VERIFY(l.x, "every numbered node is used here");
  const auto owned_here = [&](const LocalNode& n) {
    return n.first_tet >= first_tet && n.first_tet < out.tet_block[me + 1];
  };
  std::sort(local_nodes.begin(), local_nodes.end(), [&](const LocalNode& a, const LocalNode& b) {
    const bool oa = owned_here(a), ob = owned_here(b);
    return oa != ob ? oa : a.gid < b.gid;
  });
  NodeArrays& nodes = model.nodes;
  const LocalIndex n_local = local_count(local_nodes.size(), "nodes");
  nodes.has_prescribed_velocity = scene.prescribes_velocities();
  nodes.resize(n_local);
  nodes.reference_positions.clear();
  nodes.n_owned = 0;
  out.node_first_tet.resize(static_cast<std::size_t>(n_local));
  out.node_owner.resize(static_cast<std::size_t>(n_local));
  for (LocalIndex n = 0; n < n_local; ++n) {
    const LocalNode& l = local_nodes[n];
    nodes.gid[n] = l.gid;
    nodes.add_reference(n, l.x);
    std::copy_n(l.x, 3, nodes.x.data() + 3 * static_cast<std::size_t>(n));
    nodes.piece[n] = l.piece;
    out.node_first_tet[n] = l.first_tet;
    out.node_owner[n] = block_owner(out.tet_block, l.first_tet);
    if (out.node_owner[n] == me) nodes.n_owned = n + 1;
  }
  nodes.compact_references();
  std::fill(nodes.v.begin(), nodes.v.end(), 0.0);
  std::fill(nodes.f.begin(), nodes.f.end(), 0.0);
  std::fill(nodes.mass.begin(), nodes.mass.end(), 0.0);
  std::fill(nodes.constrained.begin(), nodes.constrained.end(), 0);
  std::fill(nodes.prescribed_velocity.begin(), nodes.prescribed_velocity.end(), 0.0);
  const auto local_node = [&](GlobalId gid) {
    const LocalIndex n = nodes.find(gid);
    FDEM_VERIFY(n >= 0, "a node of a local tet is local");
    return n;
  };

  // The nodes hold the positions now: the records shrink to their links before the tet arrays
  // are made (the start-up's peak would otherwise hold both).
  std::vector<TetLinks> links(records.size());
  for (std::size_t t = 0; t < records.size(); ++t) {
    const TetRecord& r = records[t];
    links[t] = {r.body, r.piece, r.mesh_tet, {r.node[0], r.node[1], r.node[2], r.node[3]}};
  }
  records = std::vector<TetRecord>{};
  local_nodes = std::vector<LocalNode>{};  // pointed into the records

  // Tets: reference shapes, viscosities; node masses summed at the owners in tet-gid order, with
  // the largest extent among each node's tets (the reach of the first halo).
  TetArrays& tets = model.tets;
  const LocalIndex n_tets = local_count(links.size(), "tetrahedra");
  tets.resize(n_tets);
  tets.n_owned = n_tets;
  tets.contact_group.resize(n_tets);
  tets.owned.assign(n_tets, 1);
  tets.active.assign(n_tets, 1);
  // A node owned here is first used here, so no tet of a lower rank uses it: its mass is the sum
  // of this block's quarters in gid order (added right away), then those of higher ranks' tets
  // (sent here, added after in gid order) — the serial builder's order.  Only the quarters for
  // nodes owned elsewhere travel.
  std::vector<double> tet_extent(static_cast<std::size_t>(n_tets));
  std::vector<FaceTet> face_tets;  // tets of bodies that joints concern
  std::vector<char> has_faces(chunks.size());
  for (std::size_t b = 0; b < chunks.size(); ++b) has_faces[b] = body_has_faces(scene, b);
  std::vector<double> node_extent(static_cast<std::size_t>(n_local), 0.0);
  std::vector<std::vector<MassPart>> parts(static_cast<std::size_t>(ranks));
  for (LocalIndex t = 0; t < n_tets; ++t) {
    const TetLinks& r = links[t];
    const std::int32_t material = scene.bodies[r.body].material;
    tets.gid[t] = first_tet + t;
    tets.material[t] = material;
    tets.piece[t] = tets.contact_group[t] = r.piece;
    Vec3 X[4];
    for (int c = 0; c < 4; ++c) {
      const LocalIndex n = local_node(number_of(keys.key(r, c)).gid);
      tets.nodes[4 * t + c] = n;
      X[c] = nodes.x0(n);
    }
    const TetSetup setup = setup_tet(X, model.materials[material]);
    Eigen::Map<Mat3>(tets.dm_inv.data() + 9 * static_cast<std::size_t>(t)) = setup.dm_inv;
    tets.volume0[t] = setup.volume;
    tets.viscosity[t] = setup.viscosity;
    Vec3 box_lo = X[0], box_hi = X[0];
    for (int c = 1; c < 4; ++c) {
      box_lo = box_lo.cwiseMin(X[c]);
      box_hi = box_hi.cwiseMax(X[c]);
    }
    tet_extent[static_cast<std::size_t>(t)] = (box_hi - box_lo).maxCoeff();
    for (int c = 0; c < 4; ++c) {
      const LocalIndex n = tets.nodes[4 * t + c];
      if (n < nodes.n_owned) {
        nodes.mass[n] += 0.25 * setup.mass;
        node_extent[static_cast<std::size_t>(n)] = std::max(
            node_extent[static_cast<std::size_t>(n)], tet_extent[static_cast<std::size_t>(t)]);
      } else {
        parts[static_cast<std::size_t>(out.node_owner[n])].push_back(
            {nodes.gid[n], tets.gid[t], 0.25 * setup.mass,
             tet_extent[static_cast<std::size_t>(t)]});
      }
    }
    if (has_faces[static_cast<std::size_t>(r.body)]) {
      FaceTet f{t, r.body, {}};
      for (int c = 0; c < 4; ++c) f.mesh_node[c] = r.node[c] - node_base[r.body];
      face_tets.push_back(f);
    }
  }
  // Contact groups: a piece, or in a `joints: all` body each tet its own, numbered after the
  // pieces in gid order (as build_model numbers them).
  {
    std::int64_t split = 0;
    for (const TetLinks& r : links) split += keys.split(r);
    const std::vector<std::int64_t> counts = comm.allgather(split);
    std::int64_t next = static_cast<std::int64_t>(model.pieces.size()) +
                        std::accumulate(counts.begin(), counts.begin() + me, std::int64_t{0});
    FDEM_VERIFY(static_cast<std::int64_t>(model.pieces.size()) +
                        std::accumulate(counts.begin(), counts.end(), std::int64_t{0}) <=
                    std::numeric_limits<std::int32_t>::max(),
                "contact groups fit 32 bits");
    for (LocalIndex t = 0; t < n_tets; ++t)
      if (keys.split(links[t])) tets.contact_group[t] = static_cast<std::int32_t>(next++);
  }
  links = std::vector<TetLinks>{};
  std::vector<MassPart> arrived = comm.exchange(parts);
  parts.clear();
  std::sort(arrived.begin(), arrived.end(), [](const MassPart& a, const MassPart& b) {
    return a.node != b.node ? a.node < b.node : a.tet < b.tet;
  });
  for (const MassPart& p : arrived) {
    FDEM_VERIFY(p.tet >= out.tet_block[me + 1], "mass quarters arrive from higher blocks");
    const LocalIndex n = local_node(p.node);
    nodes.mass[n] += p.mass;
    node_extent[static_cast<std::size_t>(n)] =
        std::max(node_extent[static_cast<std::size_t>(n)], p.extent);
  }
  release(arrived);
  // The other local nodes ask their owners for the mass and extent.
  std::vector<std::vector<GlobalId>> asks(static_cast<std::size_t>(ranks));
  for (LocalIndex n = nodes.n_owned; n < n_local; ++n)
    asks[static_cast<std::size_t>(out.node_owner[n])].push_back(nodes.gid[n]);
  std::vector<int> asker;
  const std::vector<GlobalId> asked = comm.exchange(asks, &asker);
  std::vector<std::vector<NodeMass>> answers(static_cast<std::size_t>(ranks));
  for (std::size_t i = 0; i < asked.size(); ++i) {
    const LocalIndex n = local_node(asked[i]);
    answers[static_cast<std::size_t>(asker[i])].push_back(
        {asked[i], nodes.mass[n], node_extent[static_cast<std::size_t>(n)]});
  }
  for (const NodeMass& m : comm.exchange(answers)) {
    const LocalIndex n = local_node(m.node);
    nodes.mass[n] = m.mass;
    node_extent[static_cast<std::size_t>(n)] = m.extent;
  }

  // Joints (parallel/distributed_joints; every rank knows from the scene whether there are any),
  // and the reach of each tet over the whole model.
  BlockJoints joints;
  if (std::find(has_faces.begin(), has_faces.end(), 1) != has_faces.end()) {
    std::vector<std::string> sources;
    for (const BodyChunks& body : chunks) sources.push_back(body.source);
    joints = place_block_joints(scene, sources, model, tet_extent, face_tets, out.tet_block,
                                matching_tolerance(hi - lo), comm);
  }
  release(face_tets);
  out.joints = std::move(joints.joints);
  out.n_joints = joints.n_joints;
  model.joint_laws = std::move(joints.laws);
  if (out.n_joints > 0) out.tet_joint_state = std::move(joints.bonded);
  out.tet_reach = std::move(tet_extent);
  for (LocalIndex t = 0; t < n_tets; ++t) {
    double& reach = out.tet_reach[static_cast<std::size_t>(t)];
    if (!joints.partner_extent.empty())
      reach = std::max(reach, joints.partner_extent[static_cast<std::size_t>(t)]);
    for (int c = 0; c < 4; ++c)
      reach = std::max(reach, node_extent[static_cast<std::size_t>(tets.nodes[4 * t + c])]);
  }

  // Pieces (kept at their directory ranks), velocities, constraints, force order.
  sum_pieces_by_directory(model, comm);
  set_dashpot_masses(model);
  set_initial_velocities(scene, model);
  keep_directory_block(model.pieces, comm);
  build_tet_force_order(tets, model.tet_force_order);
  apply_constraints(scene, model);
  return out;
}

double distributed_nth_value(const std::vector<double>& values, std::int64_t k,
                             const Communicator& comm) {
  // Non-negative doubles order as their bit patterns: find the smallest pattern v with more than
  // k values ≤ v.
  std::vector<std::uint64_t> bits(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    FDEM_VERIFY(values[i] >= 0.0, "distributed_nth_value takes non-negative values");
    std::memcpy(&bits[i], &values[i], sizeof(double));
  }
  std::uint64_t lo = 0, hi = std::numeric_limits<std::uint64_t>::max() >> 1;  // (lo, hi]
  while (lo < hi) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    std::int64_t count = 0;
    for (std::uint64_t b : bits) count += b <= mid;
    if (comm.sum(count) > k)
      hi = mid;
    else
      lo = mid + 1;
  }
  double out;
  std::memcpy(&out, &lo, sizeof(double));
  return out;
}

}  // namespace fdem
