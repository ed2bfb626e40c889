#include "parallel/contact_faces_exchange.hpp"

#include <cstdint>
#include <vector>

#include "core/contact_faces.hpp"

namespace fdem {
namespace {

// A directory rank for a key of 64-bit numbers (splitmix64 steps).
int directory_of(const std::int64_t* key, int n, int ranks) {
  std::uint64_t h = 0x9E3779B97F4A7C15ULL;
  for (int i = 0; i < n; ++i) {
    h ^= static_cast<std::uint64_t>(key[i]) + 0x9E3779B97F4A7C15ULL + (h << 6) + (h >> 2);
    h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ULL;
    h = (h ^ (h >> 27)) * 0x94D049BB133111EBULL;
    h ^= h >> 31;
  }
  return static_cast<int>(h % static_cast<std::uint64_t>(ranks));
}

// Records to their directory ranks (`key`) or back to their sources.
template <class Record, class Rank>
std::vector<Record> send(const std::vector<Record>& records, Rank rank_of,
                         const Communicator& comm) {
  std::vector<std::vector<Record>> outbox(static_cast<std::size_t>(comm.size()));
  for (const Record& r : records) outbox[static_cast<std::size_t>(rank_of(r))].push_back(r);
  return comm.exchange(outbox);
}

}  // namespace

void compute_contact_faces(Model& block, const Communicator& comm) {
  const int ranks = comm.size();
  const auto back_to_source = [](const auto& r) { return static_cast<int>(r.source); };
  std::vector<FaceRecord> faces = send(
      face_records(block, comm.rank()),
      [&](const FaceRecord& r) {
        const std::int64_t key[4] = {r.group, r.node[0], r.node[1], r.node[2]};
        return directory_of(key, 4, ranks);
      },
      comm);
  keep_surface_faces(faces);
  faces = send(faces, back_to_source, comm);
  std::vector<EdgeRecord> edges = send(
      edge_records(block, faces),
      [&](const EdgeRecord& r) {
        const std::int64_t key[3] = {r.group, r.node[0], r.node[1]};
        return directory_of(key, 3, ranks);
      },
      comm);
  keep_fold_edges(edges);
  edges = send(edges, back_to_source, comm);
  std::vector<VertexRecord> vertices = send(
      vertex_records(block, faces, edges),
      [&](const VertexRecord& r) {
        const std::int64_t key[2] = {r.group, r.node};
        return directory_of(key, 2, ranks);
      },
      comm);
  keep_fold_vertices(vertices);
  vertices = send(vertices, back_to_source, comm);
  set_contact_faces(block, faces, edges, vertices);
}

}  // namespace fdem
