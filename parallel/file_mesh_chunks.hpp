// A body meshed by a model file (parallel/model_file.hpp) as a chunk plan for the distributed
// start-up (parallel/distributed_build): rank r reads the r-th equal slice of the file's tets by
// hyperslab and only the coordinates of the nodes its slice uses; pieces are found by a
// distributed union-find (parallel/distributed_pieces).  No rank reads or holds the whole mesh.
#pragma once

#include <string>

#include "core/model_builder.hpp"
#include "parallel/communicator.hpp"

namespace fdem {

// Collective.  The chunk plan of a body with `mesh: {file: <path>, physical: <physical>}`: one
// chunk per rank, chunk r on rank r (BodyChunks::chunk_rank), its tets those of the selection in
// rank r's slice, with the serial reader's numbering: nodes by their row in the file, tets by their
// index among the selected tets, pieces as connected_pieces numbers them, tags for messages.
// `source` names the mesh in messages about its tets (the scene's file [physical]).  A damaged
// file, a tet referencing a node beyond the table, a coordinate that is NaN, an unknown group —
// found on any rank — is a CollectiveInputError on every rank naming the file and what is wrong.
BodyChunks file_mesh_chunks(const std::string& path, const std::string& physical,
                            const std::string& source, const Communicator& comm);

}  // namespace fdem
