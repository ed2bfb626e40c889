// Distributed start-up: every rank generates only some chunks of the bodies' meshes and ends up
// holding one contiguous block of tet global ids with their nodes — no rank ever holds the whole
// model (docs/parallel.md, "Distributed start-up").
//
// The result is the model build_model (core/model_builder) makes, cut into blocks, bit for bit:
// the same tet gids (Morton order of the centroids in the box of all nodes, ties by body and mesh
// tet), the same node gids (order of first use by the ordered tets), the same lumped masses
// (each node's tets summed in gid order), the same piece masses and centroids (summed along the
// ranks in gid order), velocities, constraints, reference shapes and viscosities.
//
// The steps, each a bounded all-to-all (data per rank ∝ its part, plus O(P) tables):
//   1 chunks are dealt to ranks by tet count; each rank generates its chunks and checks shapes;
//   2 the bounding box of all nodes (min/max reduction) gives every tet its Morton key;
//   3 a sample sort puts the tets in key order, cut into equal blocks: block r is rank r's;
//   4 nodes meet at a directory rank (by mesh node number) that learns each node's first use,
//     hands it to the rank of that tet, which numbers the nodes it owns; the numbers go back to
//     every rank that uses the node;
//   5 lumped masses are summed at the node's owner in tet-gid order; pieces in a chain of ranks.
#pragma once

#include <cstdint>
#include <vector>

#include "core/model.hpp"
#include "core/model_builder.hpp"
#include "core/scene.hpp"
#include "parallel/communicator.hpp"

namespace fdem {

// One rank's block of the model and what the distribution needs to know about its nodes.
struct DistributedModel {
  // Owned tets (tets.owned and tets.active all 1) and every node they use: the nodes this rank
  // owns (their first user is here) first, then the others, each range in ascending gid.  Every
  // node has its mass, velocity and constraints.
  Model model;
  std::vector<GlobalId> node_first_tet;  // per local node: gid of the first tet that uses it
  std::vector<std::int32_t> node_owner;  // per local node: the rank that owns it
  std::vector<GlobalId> tet_block;       // size()+1 entries: rank r owns tet gids [r, r+1)
  GlobalId n_nodes = 0, n_tets = 0;      // of the whole model
};

// Collective.  `chunks`: one per body of `scene` (drivers/mesh_generators body_chunks).  Every
// rank passes the same scene and chunk plans.  Throws (collectively) InputError for a bad mesh,
// with the body and tet as the serial builder names them.  Bodies with joints are not supported
// here (the caller keeps the whole-model start for them).
DistributedModel build_distributed_model(const Scene& scene, const std::vector<BodyChunks>& chunks,
                                         const Communicator& comm);

// Collective: the k-th smallest (0-based) of the values of all ranks, exactly, whatever the rank
// count (a bisection on the bit patterns of non-negative doubles, one reduction per bit).
double distributed_nth_value(const std::vector<double>& values, std::int64_t k,
                             const Communicator& comm);

}  // namespace fdem
