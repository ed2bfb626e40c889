// Steps 1-4 of the distributed start-up (parallel/distributed_build.hpp).
#include "parallel/distributed_build_steps.hpp"

#include <algorithm>
#include <numeric>

#include "core/error.hpp"

namespace fdem::distributed_build_steps {

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

}  // namespace fdem::distributed_build_steps
