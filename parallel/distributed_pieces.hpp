// Connected pieces of a tet mesh whose tets are spread over the ranks in slices, found without any
// rank holding the mesh: a distributed union-find over node ids (docs/parallel.md, "Gmsh meshes
// at scale").  The pieces are numbered as core/model_builder's connected_pieces numbers them on
// the whole mesh: in the order of each piece's first tet.
#pragma once

#include <cstdint>
#include <vector>

#include "parallel/communicator.hpp"

namespace fdem {

// Collective.  `tets`: 4 node ids per local tet, ids in [0, n_nodes).  The mesh's tets are the
// ranks' tets in rank order (rank r's first tet is the mesh's tet `first_tet`).  Returns each
// local tet's piece; `n_pieces` receives the count (the same on every rank).
//
// Each rank joins its tets' nodes into local components (a union-find); every node is reported
// with its component's smallest node id to the node's directory rank (ids in equal blocks), which
// links the components that meet there.  Those links are contracted by rounds of hooking each
// root onto the smallest root it is linked to and pointer jumping, with the parents kept at the
// directory ranks; each round removes at least one root per remaining link.  A piece's number is
// its first tet's rank among all pieces' first tets (an exclusive scan of counts).  Messages per
// rank are bounded by its own tets and nodes, plus O(P) counts.
std::vector<std::int32_t> distributed_pieces(const std::vector<std::int64_t>& tets,
                                             std::int64_t n_nodes, std::int64_t first_tet,
                                             const Communicator& comm, std::int32_t* n_pieces);

}  // namespace fdem
