// Distributed start-up: every rank generates only some chunks of the bodies' meshes and ends up
// holding one contiguous block of tet global ids with their nodes — no rank ever holds the whole
// model (docs/parallel.md, "Distributed start-up").
//
// The result is the model build_model (core/model_builder) makes, cut into blocks, bit for bit:
// the same tet gids (Morton order of the centroids in the box of all nodes, ties by body and mesh
// tet), the same node gids (order of first use by the ordered tets), the same lumped masses
// (each node's tets summed in gid order), the same piece masses and centroids (summed in gid
// order along the ranks holding each piece's tets), velocities, constraints, reference shapes and
// viscosities.
//
// The steps, each a bounded all-to-all (data per rank ∝ its part, plus O(P) tables):
//   1 chunks are dealt to ranks by tet count; each rank generates its chunks and checks shapes;
//   2 the bounding box of all nodes (min/max reduction) gives every tet its Morton key;
//   3 a sample sort puts the tets in key order, cut into equal blocks: block r is rank r's;
//   4 nodes meet at a directory rank (by mesh node number) that learns each node's first use,
//     hands it to the rank of that tet, which numbers the nodes it owns; the numbers go back to
//     every rank that uses the node;
//   5 lumped masses are summed at the node's owner in tet-gid order; each piece's mass and centroid
//     along the chain of ranks holding its tets, kept at its directory rank
//     (parallel/piece_directory).
#pragma once

#include <cstdint>
#include <vector>

#include "core/model.hpp"
#include "core/model_builder.hpp"
#include "core/scene.hpp"
#include "parallel/communicator.hpp"

namespace fdem {

// A cohesive joint as the distributed start-up leaves it, at the owner of its tet A: what
// JointArrays holds for it, with tets and nodes as global ids (tet B and its nodes may be on
// another rank).  Intact: not broken, damage 0, failure time −1.
struct StartJoint {
  GlobalId gid;
  GlobalId tets[2];   // A (the smaller gid), B
  GlobalId nodes[6];  // a0 a1 a2 b0 b1 b2, b_i coincident with a_i
  double area0;       // m²
  std::int32_t law;   // index into model.joint_laws
};

// One rank's block of the model and what the distribution needs to know about its nodes.
struct DistributedModel {
  // Owned tets (tets.owned and tets.active all 1) and every node they use: the nodes this rank
  // owns (their first user is here) first, then the others, each range in ascending gid.  Every
  // node has its mass, velocity and constraints.  model.joint_laws is the whole model's; the
  // joints are in `joints` (model.joints stays empty); model.pieces keeps the rank's directory
  // block of pieces (parallel/piece_directory).
  Model model;
  std::vector<GlobalId> node_first_tet;  // per local node: gid of the first tet that uses it
  std::vector<std::int32_t> node_owner;  // per local node: the rank that owns it
  std::vector<GlobalId> tet_block;       // size()+1 entries: rank r owns tet gids [r, r+1)
  GlobalId n_nodes = 0, n_tets = 0;      // of the whole model
  // Joints whose tet A is in this block, in ascending gid (= ascending (gid A, gid B)).
  std::vector<StartJoint> joints;
  GlobalId n_joints = 0;  // of the whole model
  // Per local tet: 1 when a joint bonds it (the contact stage's "intact" joint state), 0 when not;
  // empty when the model has no joints.
  std::vector<std::uint8_t> tet_joint_state;
  // Per local tet: the largest box extent (m, at x0) among the tets that share a node with it or
  // are bonded to it by a joint, itself included, over the whole model — the reach the
  // distribution's first halo needs (tets of other blocks included).
  std::vector<double> tet_reach;
};

// Collective.  `chunks`: one per body of `scene` (drivers/mesh_generators body_chunks).  Every
// rank passes the same scene and chunk plans.  Throws (collectively) InputError for a bad mesh,
// with the body and tet as the serial builder names them, and for joints that cannot be placed
// (a triangle of more than two tets, touching pieces or an interface without a shared triangle)
// with the serial builder's message.
DistributedModel build_distributed_model(const Scene& scene, const std::vector<BodyChunks>& chunks,
                                         const Communicator& comm);

// Collective: the k-th smallest (0-based) of the values of all ranks, exactly, whatever the rank
// count (a bisection on the bit patterns of non-negative doubles, one reduction per bit).
double distributed_nth_value(const std::vector<double>& values, std::int64_t k,
                             const Communicator& comm);

}  // namespace fdem
