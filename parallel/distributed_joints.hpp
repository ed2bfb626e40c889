// Cohesive joints of the distributed start-up (parallel/distributed_build): the joints
// build_model (core/model_builder: place_joints) places, found without any rank holding a whole
// mesh, each ending at the owner of its tet A.
//
// Every face of a tet of a body that joints concern travels to a *face directory* rank (a hash of
// the body and the face's sorted mesh node numbers) — except that two faces of one block that
// pair up are paired where they are, and only their count travels.  There
//   - a face of three or more tets is a non-manifold mesh (the serial message);
//   - a face of two tets in a `joints: all` body is a joint;
//   - a face of one tet is a boundary face: its tet's owner is told, and sends the face's nodes to
//     a *position directory* rank (a hash of a block of 1024³ cells of the builder's tolerance
//     grid; a node near a block's side goes to the neighbouring blocks' ranks too, so each rank
//     sees every node within one tolerance cell of the nodes it answers for).  That rank finds,
//     as the serial builder does, the boundary nodes within the tolerance of each node — of other
//     pieces of its body (`joints: interfaces`) or of an interface's other body — and answers
//     with the lowest-numbered one per piece or interface;
//   - with the partners of its three nodes, the owner asks the face directory of the partner
//     triangle whether it is a boundary face; if so, that is a joint.
// Joints go to the owner of tet A (the smaller gid), which orients them, computes their areas
// and size bins with the serial builder's code; laws are numbered in ascending (group, bin) from
// an allgather of the (few) keys, joint gids by an exclusive prefix sum of the counts.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/model.hpp"
#include "core/scene.hpp"
#include "parallel/communicator.hpp"
#include "parallel/distributed_build.hpp"

namespace fdem {

// A tet of this rank's block in a body that joints concern (`joints: all`, `joints:
// interfaces`, or a side of an `interfaces:` entry).
struct FaceTet {
  LocalIndex tet;  // local index in the block
  std::int32_t body;
  std::int64_t mesh_node[4];  // its corners' numbers in the body's mesh, in corner order
};

struct BlockJoints {
  std::vector<StartJoint> joints;      // tet A in this block, ascending gid
  std::vector<JointLawSpec> laws;      // of the whole model
  GlobalId n_joints = 0;               // of the whole model
  std::vector<std::uint8_t> bonded;    // per local tet: its TetJointState (intact or enclosed)
  std::vector<double> partner_extent;  // per local tet: largest extent (m) of a tet bonded to it
};

// Whether `body` is one that joints concern.
bool body_has_faces(const Scene& scene, std::size_t body);

// Collective.  `block`: this rank's tets (gid = tet_block[rank] + local index, volume0, piece,
// nodes) and their nodes (gid, x0); `tet_extent`: per local tet its largest box side (m);
// `face_tets`: the local tets of bodies with faces, by ascending local index; `sources`: per body
// its mesh's source (for messages); `tol`: matching tolerance (m).  Throws (collectively) the
// serial builder's InputError when joints cannot be placed.
BlockJoints place_block_joints(const Scene& scene, const std::vector<std::string>& sources,
                               const Model& block, const std::vector<double>& tet_extent,
                               const std::vector<FaceTet>& face_tets,
                               const std::vector<GlobalId>& tet_block, double tol,
                               const Communicator& comm);

}  // namespace fdem
