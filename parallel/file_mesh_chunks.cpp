#include "parallel/file_mesh_chunks.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <optional>

#include "core/error.hpp"
#include "io/gmsh_parser.hpp"
#include "parallel/checkpoint_checksum.hpp"
#include "parallel/distributed_pieces.hpp"
#include "parallel/model_file_reader.hpp"

namespace fdem {

namespace {

using namespace model_file;

constexpr std::int64_t window_rows = 1 << 16;  // node rows read at a time
constexpr std::int64_t gap_rows = 32;          // unused rows read to join two runs of used rows

// Checksums of this rank's rows: its slice of the tets and its block of the nodes (read in
// windows, so that every row of the file is checked by exactly one rank).
std::vector<std::uint64_t> local_checksums(const Reader& file, std::int64_t first,
                                           const std::vector<std::int64_t>& nodes,
                                           const std::vector<std::int64_t>& tags,
                                           const std::vector<std::int32_t>& entity,
                                           const std::vector<std::int32_t>& physical,
                                           const Communicator& comm) {
  const auto row0 = static_cast<std::uint64_t>(first);
  std::vector<std::uint64_t> sums = {rows_checksum(tet_nodes.name, nodes, 4, row0),
                                     rows_checksum(tet_tag.name, tags, 1, row0),
                                     rows_checksum(tet_entity.name, entity, 1, row0),
                                     rows_checksum(tet_physical.name, physical, 1, row0),
                                     0,
                                     0};
  const std::int64_t n = file.header().n_nodes;
  const std::int64_t end = mul_div(n, comm.rank() + 1, comm.size());
  for (std::int64_t at = mul_div(n, comm.rank(), comm.size()); at < end; at += window_rows) {
    const std::int64_t rows = std::min(window_rows, end - at);
    sums[4] += rows_checksum(node_tag.name, file.rows<std::int64_t>(node_tag, at, rows), 1,
                             static_cast<std::uint64_t>(at));
    sums[5] += rows_checksum(node_x.name, file.rows<double>(node_x, at, rows), 3,
                             static_cast<std::uint64_t>(at));
  }
  return sums;
}

// Coordinates of the node rows `ids` (ascending), read in runs of nearby rows.
std::vector<double> read_coordinates(const Reader& file, const std::vector<std::int64_t>& ids,
                                     const std::string& label) {
  std::vector<double> coords(3 * ids.size());
  for (std::size_t i = 0; i < ids.size();) {
    std::size_t j = i + 1;
    while (j < ids.size() && ids[j] - ids[j - 1] <= gap_rows && ids[j] - ids[i] < window_rows) ++j;
    const std::vector<double> rows = file.rows<double>(node_x, ids[i], ids[j - 1] - ids[i] + 1);
    for (std::size_t k = i; k < j; ++k)
      for (int d = 0; d < 3; ++d) {
        const double x = rows[static_cast<std::size_t>(3 * (ids[k] - ids[i]) + d)];
        if (!std::isfinite(x))
          throw InputError(
              non_finite_node_message(label, file.rows<std::int64_t>(node_tag, ids[k], 1)[0]));
        coords[3 * k + static_cast<std::size_t>(d)] = x;
      }
    i = j;
  }
  return coords;
}

}  // namespace

BodyChunks file_mesh_chunks(const std::string& path, const std::string& physical,
                            const std::string& source, const Communicator& comm) {
  const Reader file(path, &comm);
  const std::string label = file.label();
  const int ranks = comm.size(), me = comm.rank();
  const std::int64_t n = file.header().n_nodes, m = file.header().n_tets;
  std::optional<GmshSelection> selection;
  comm.run_collectively([&] {
    selection.emplace(file.tables(), physical, label);
    if (m == 0) throw InputError(no_tetrahedra_message(label));
  });

  // 1. This rank's slice of the tets, its node rows checked against the table.
  const std::int64_t first = mul_div(m, me, ranks), count = mul_div(m, me + 1, ranks) - first;
  std::vector<std::int64_t> nodes, tags;
  std::vector<std::int32_t> entity, physicals;
  comm.run_collectively([&] {
    nodes = file.rows<std::int64_t>(tet_nodes, first, count);
    tags = file.rows<std::int64_t>(tet_tag, first, count);
    entity = file.rows<std::int32_t>(tet_entity, first, count);
    physicals = file.rows<std::int32_t>(tet_physical, first, count);
    for (std::size_t i = 0; i < nodes.size(); ++i)
      if (nodes[i] < 0 || nodes[i] >= n)
        throw InputError(
            node_row_message(label, tags[i / 4], first + std::int64_t(i / 4), nodes[i], n));
  });

  // 2. Every row checked against its dataset's checksum, each by one rank.
  std::vector<std::uint64_t> sums;
  comm.run_collectively(
      [&] { sums = local_checksums(file, first, nodes, tags, entity, physicals, comm); });
  comm.sum_in_place(sums);  // unsigned: wraps mod 2^64, the same on any rank count
  comm.run_collectively([&] {
    const DatasetInfo order[] = {tet_nodes, tet_tag, tet_entity, tet_physical, node_tag, node_x};
    for (std::size_t i = 0; i < sums.size(); ++i)
      if (sums[i] != file.stored_checksum(order[i])) file.corrupt(order[i]);
  });
  physicals.clear();

  // 3. The selected tets, numbered in file order across the ranks.
  std::vector<std::int64_t> kept_nodes, kept_tags;
  for (std::size_t t = 0; t < tags.size(); ++t)
    if (selection->kept(entity[t])) {
      kept_nodes.insert(kept_nodes.end(), nodes.begin() + 4 * std::ptrdiff_t(t),
                        nodes.begin() + 4 * std::ptrdiff_t(t) + 4);
      kept_tags.push_back(tags[t]);
    }
  release(nodes);
  release(tags);
  release(entity);
  const std::vector<std::int64_t> kept =
      comm.allgather(static_cast<std::int64_t>(kept_tags.size()));
  const std::int64_t kept_first = std::accumulate(kept.begin(), kept.begin() + me, std::int64_t{0});
  const std::int64_t kept_total = std::accumulate(kept.begin(), kept.end(), std::int64_t{0});
  comm.run_collectively([&] {
    if (kept_total == 0) throw InputError(selection->empty_message(m));
  });

  // 4. Pieces, numbered as the serial builder numbers them.
  BodyChunks plan;
  std::vector<std::int32_t> pieces =
      distributed_pieces(kept_nodes, n, kept_first, comm, &plan.n_pieces);

  // 5. The coordinates of the nodes this slice uses, and the box of all used nodes.
  std::vector<std::int64_t> ids = kept_nodes;
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  std::vector<double> coords;
  comm.run_collectively([&] {
    coords = read_coordinates(file, ids, label);
    if (ids.size() > static_cast<std::size_t>(std::numeric_limits<LocalIndex>::max()))
      throw InputError(label + ": one rank's slice uses more than 2^31-1 nodes; run on more ranks");
  });
  std::vector<double> lo(3, 1e300), hi(3, -1e300);
  for (std::size_t i = 0; i < ids.size(); ++i)
    for (int d = 0; d < 3; ++d) {
      lo[static_cast<std::size_t>(d)] =
          std::min(lo[static_cast<std::size_t>(d)], coords[3 * i + d]);
      hi[static_cast<std::size_t>(d)] =
          std::max(hi[static_cast<std::size_t>(d)], coords[3 * i + d]);
    }
  comm.min_in_place(lo);
  comm.max_in_place(hi);

  auto chunk = std::make_shared<MeshChunk>();
  chunk->mesh.source = source;
  chunk->mesh.coords = std::move(coords);
  local_count(ids.size(), "nodes");  // chunk node numbers are local indices
  chunk->mesh.tets.reserve(kept_nodes.size());
  for (std::int64_t id : kept_nodes)
    chunk->mesh.tets.push_back(
        static_cast<LocalIndex>(std::lower_bound(ids.begin(), ids.end(), id) - ids.begin()));
  chunk->mesh.source_tags = std::move(kept_tags);
  chunk->node_id = std::move(ids);
  chunk->tet_id.resize(chunk->mesh.source_tags.size());
  std::iota(chunk->tet_id.begin(), chunk->tet_id.end(), kept_first);
  chunk->tet_piece = std::move(pieces);

  plan.n_nodes = n;
  plan.lo = Vec3(lo[0], lo[1], lo[2]);
  plan.hi = Vec3(hi[0], hi[1], hi[2]);
  plan.chunk_tets = kept;
  plan.chunk_centre.assign(static_cast<std::size_t>(ranks), 0.5 * (plan.lo + plan.hi));
  plan.chunk_rank.resize(static_cast<std::size_t>(ranks));
  std::iota(plan.chunk_rank.begin(), plan.chunk_rank.end(), 0);
  plan.generate = [chunk, me](std::int64_t c) {
    FDEM_VERIFY(c == me, "a model file's slice is generated on its own rank");
    return std::move(*chunk);
  };
  return plan;
}

}  // namespace fdem
