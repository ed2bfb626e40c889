// Per-piece sums over the owned nodes behind the rows of bodies.csv: mass, centroid, velocity and
// the best-fit rotation of every discrete element.  The sums are exact (core/exact_sum), so they
// do not depend on the order of the nodes or on how they are spread over ranks: one process adds
// all of them (core/dynamics: piece_motions); on N ranks each rank adds its owned nodes and the
// piece's directory rank merges the partial sums (parallel/piece_directory), with the same result
// bit for bit.
#pragma once

#include <cstdint>
#include <vector>

#include "core/exact_sum.hpp"
#include "core/model.hpp"
#include "core/types.hpp"

namespace fdem {

// Mass-weighted position, velocity and rotation of a piece (for bodies.csv and tests).
struct PieceMotion {
  Vec3 centroid = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Vec3 rotation = Vec3::Zero();  // rotation vector (axis × angle, rad) of the best-fit rotation
};

// First moments of a piece's nodes: Σm, Σm·x, Σm·v, Σm·x0.
struct PieceMoments {
  ExactSum mass, position[3], momentum[3], reference[3];

  void add(const PieceMoments& other);
  void append_words(std::vector<std::int64_t>& out) const;
  static PieceMoments from_words(const std::int64_t*& words);
};

// The centroid now and at t = 0 and the velocity of the centroid, from the exact moments.
struct PieceCentres {
  Vec3 centroid = Vec3::Zero(), velocity = Vec3::Zero(), reference = Vec3::Zero();
};
PieceCentres centres_of(const PieceMoments& moments);

// Second moment Σ m·(x − c)(x0 − c0)ᵀ about the centres (column-major), for the rotation.
struct PieceSpread {
  ExactSum covariance[9];

  void add(const PieceSpread& other);
  void append_words(std::vector<std::int64_t>& out) const;
  static PieceSpread from_words(const std::int64_t*& words);
};
// Best-fit rotation (Kabsch) as a rotation vector.
Vec3 rotation_of(const PieceSpread& spread);

// The owned nodes grouped by piece: ids ascending, piece ids[i] has the owned nodes
// nodes[first[i]] .. nodes[first[i + 1] − 1] (ascending local index).  Sums are made one piece at a
// time from it, so only one piece's exact sums exist at once.
struct OwnedPieces {
  std::vector<std::int32_t> ids;
  std::vector<std::int32_t> first;
  std::vector<LocalIndex> nodes;
};
OwnedPieces owned_pieces(const NodeArrays& nodes);

// The moments of the owned nodes of piece owned.ids[i].
PieceMoments piece_moments(const NodeArrays& nodes, const OwnedPieces& owned, std::size_t i);
// Their spread about `centres`.
PieceSpread piece_spread(const NodeArrays& nodes, const OwnedPieces& owned, std::size_t i,
                         const PieceCentres& centres);

}  // namespace fdem
