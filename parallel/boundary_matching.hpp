// Boundary nodes matched by position across ranks, for the joints of the distributed start-up
// (parallel/distributed_joints): the partners build_model (core/joint_placement) finds for
// touching pieces and interfaces, without any rank holding a whole mesh.
//
// Positions are binned into the builder's tolerance cells (core/joint_placement:
// tolerance_cell), and blocks of 1024³ cells are dealt to ranks by a hash.  Each node goes to the
// rank of its own block, which answers for it, and to the ranks of the neighbouring blocks when
// it lies in a cell on its block's side: so the answering rank sees every node within one cell of
// it, all a match within the tolerance can be.  It then finds, as the serial builder does, the
// nodes within the tolerance — boundary nodes of other pieces of the same body (`joints:
// interfaces`), or of an interface's body B for a node of its body A — and keeps the
// lowest-numbered one per piece or interface.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/scene.hpp"
#include "parallel/communicator.hpp"

namespace fdem {

// A boundary node of a body whose faces are matched: its mesh node in the body and its piece.
struct BoundaryPoint {
  std::int32_t body, piece;
  std::int64_t mesh_node;
  double x[3];  // m
};

// A boundary node's partner: the lowest-numbered boundary node within the tolerance of piece
// `target` (>= 0, > the node's piece) of the same body, or of body B of interface −1 − target.
struct NodeMatch {
  std::int64_t mesh_node, partner;
  std::int32_t body, target;
};

// Collective.  `points`: the boundary nodes this rank asks about, each (body, mesh node) once.
// Returns their partners, sorted by (body, mesh node, target).  A point whose tolerance cell does
// not fit 64 bits takes no part: `far` (sized like `points`) gets tolerance_cell's message for
// it, and an empty string for the others.
std::vector<NodeMatch> match_boundary_points(const Scene& scene,
                                             const std::vector<BoundaryPoint>& points, double tol,
                                             const Communicator& comm,
                                             std::vector<std::string>* far);

// NodeMatch order: (body, mesh node, target).
bool match_order(const NodeMatch& p, const NodeMatch& q);

}  // namespace fdem
