// Enclosed tets of the distributed start-up (parallel/distributed_joints): tets of a `joints: all`
// body none of whose corners lies on the body mesh's boundary — what build_model
// (core/joint_placement) marks in TetArrays::enclosed — found without any rank holding a whole
// mesh.  The face directories know the boundary faces (faces of one tet); their mesh nodes go to
// a *node directory* rank (a hash of the body and the mesh node), which each rank then asks about
// the corners of its jointed tets, each (body, mesh node) once.
#pragma once

#include <cstdint>
#include <vector>

#include "parallel/communicator.hpp"
#include "parallel/distributed_joints.hpp"

namespace fdem {

// A mesh node of a boundary face of a `joints: all` body.
struct BoundaryMeshNode {
  std::int64_t body;  // 64-bit: the struct travels as bytes, with no padding
  std::int64_t node;
};

// Collective.  `boundary`: the mesh nodes of the boundary faces this rank's face directory
// answers for (repeats allowed); `face_tets`: this rank's tets of bodies with faces; `jointed`:
// per body, whether it is a `joints: all` body.  Returns per face tet 1 when it is enclosed.
std::vector<std::uint8_t> enclosed_face_tets(std::vector<BoundaryMeshNode> boundary,
                                             const std::vector<FaceTet>& face_tets,
                                             const std::vector<char>& jointed,
                                             const Communicator& comm);

}  // namespace fdem
