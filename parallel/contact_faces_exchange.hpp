// TetArrays::contact_faces (core/contact_faces.hpp) for the distributed start, where no rank holds
// a whole contact group: face records meet at a directory rank (a hash of their key), which keeps
// the surface faces and returns them to the tets' ranks; the surface faces' edges meet the same
// way, and the folds go back.  Two bounded all-to-alls each; the bits are build_model's.
#pragma once

#include "core/model.hpp"
#include "parallel/communicator.hpp"

namespace fdem {

// Collective.  `block`: this rank's owned tets (every one owned) and their nodes, with global
// node gids and reference positions.  Sets block.tets.contact_faces.
void compute_contact_faces(Model& block, const Communicator& comm);

}  // namespace fdem
