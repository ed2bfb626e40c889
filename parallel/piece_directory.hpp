// Piece data on N ranks without a table of every piece (docs/parallel.md, "Pieces").  Piece ids
// are cut into equal contiguous blocks (GidBlocks over the piece count); piece p's *directory
// rank*, the one whose block holds p, keeps p's mass and reference centroid (Model::pieces keeps
// that block) and computes p's rows of bodies.csv.  What a rank sends and receives is bounded by
// the pieces of its own tets and nodes and by its block, plus O(P) counts.
#pragma once

#include <cstdint>
#include <vector>

#include "core/model.hpp"
#include "core/piece_moments.hpp"
#include "parallel/communicator.hpp"

namespace fdem {

// Piece ids [begin, end) of a rank's directory block.
struct PieceBlock {
  std::int32_t begin = 0, end = 0;
};
PieceBlock piece_directory_block(const PieceTable& pieces, const Communicator& comm);

// Keeps the mass and centroid of the rank's directory block only.
void keep_directory_block(PieceTable& pieces, const Communicator& comm);

// Collective, at the distributed start-up: piece masses and reference centroids summed as the
// serial builder sums them, tet by tet in ascending gid.  `model` holds this rank's block of tet
// gids (the blocks ascend with the rank; tets in ascending gid), with node positions and
// materials; model.pieces knows the bodies.  The directory tells each rank, per piece of its tets,
// the previous and next rank holding tets of that piece; the running sums pass along that chain,
// and the last rank sends them to the directory, which finishes them and sends them back to
// every holder.  Afterwards model.pieces keeps the directory block and the pieces of the local
// tets (for the initial velocities; keep_directory_block drops the latter).
void sum_pieces_by_directory(Model& model, const Communicator& comm);

// Collective: the motion of every piece of this rank's directory block, in id order, from the
// owned nodes of all ranks: each rank sends its exact partial moments to the directory, which
// merges them, returns the centres, and merges the spreads about them — bit for bit the
// piece_motions (core/dynamics) of one process.
struct BlockMotions {
  std::int32_t first = 0;  // id of motion[0]
  std::vector<PieceMotion> motion;
};
BlockMotions directory_piece_motions(const Model& model, const Communicator& comm);

}  // namespace fdem
