// Which faces of each tet lie on the surface of its contact group, and which of their edges are
// folds of that surface: the per-tet bits (TetArrays::contact_faces) that corner contact
// (contact/corner_contact.hpp) reads, computed once from the reference mesh.
//
// Face records are sorted by (group, sorted node gids): a key held once is a surface face.  Each
// surface face's three edges, with the face's reference outward normal, are sorted by (group,
// edge node gids): an edge of exactly two surface faces whose normals differ by at most
// kFoldAngleDegrees is flat; every other edge of a surface face is a fold.  The ends of the fold
// The corners of the surface faces are sorted by (group, node gid): where a fold edge of a side of
// the surface (faces whose normals lie within kFoldAngleDegrees) ends, the vertex is a fold vertex
// of each of that side's faces there, and the one with the least (tet gid, face) owns its zone. The
// same records serve one rank (contact_face_bits) and the distributed start, which sorts them at
// directory ranks (parallel/contact_faces_exchange.hpp): the bits are those of the whole model
// either way.
#pragma once

#include <cstdint>
#include <vector>

#include "core/model.hpp"

namespace fdem {

// Per tet two 32-bit values (TetArrays::contact_faces), read as one 64-bit set of bits.
namespace contact_face_bits {
// Face f (opposite corner f) lies on its contact group's surface: no other tet of the group has it.
constexpr std::uint64_t surface(int f) {
  return std::uint64_t{1} << f;
}
// Edge e of face f (opposite the face's e-th corner; the face's corners are the other three in
// increasing order) is a fold of the surface.
constexpr std::uint64_t fold(int f, int e) {
  return std::uint64_t{1} << (4 + 3 * f + e);
}
// Corner c of face f (its c-th corner) is a vertex of a fold edge of the face's side of the
// surface (the faces at the vertex whose normals lie within kFoldAngleDegrees).
constexpr std::uint64_t fold_vertex(int f, int c) {
  return std::uint64_t{1} << (32 + 3 * f + c);
}
// ... and of that side's faces at the vertex this one (the least tet gid, then face) holds the
// corners near the vertex (corner_contact.hpp).
constexpr std::uint64_t zone_owner(int f, int c) {
  return std::uint64_t{1} << (44 + 3 * f + c);
}
}  // namespace contact_face_bits

constexpr double kFoldAngleDegrees = 10.0;

// The corners of face f of a tet (the three others, increasing).
inline void face_corners(int f, int out[3]) {
  int k = 0;
  for (int c = 0; c < 4; ++c)
    if (c != f) out[k++] = c;
}

// A face of a tet: its group and sorted node gids (the key), and whose it is.  Plain 64-bit
// fields: records travel as bytes between ranks.
struct FaceRecord {
  std::int64_t group, node[3];
  std::int64_t tet;     // gid
  std::int64_t source;  // the rank that holds the tet
  std::int64_t face;    // 0–3
};

// An edge of a surface face: its group and ordered node gids (the key), the face's reference
// outward normal, and whose it is.
struct EdgeRecord {
  std::int64_t group, node[2];
  std::int64_t tet, source, face_edge;  // face_edge = 3·face + edge
  double normal[3];
};

// The faces of the owned tets (tets.is_owned) of `model`.
std::vector<FaceRecord> face_records(const Model& model, int source);
// Sorts the records by key and keeps those whose key is held once (the surface faces).
void keep_surface_faces(std::vector<FaceRecord>& records);
// The edges of the given surface faces of `model`'s tets (found by gid), with reference normals.
std::vector<EdgeRecord> edge_records(const Model& model, const std::vector<FaceRecord>& surface);
// Sorts the records by key and keeps the folds.
void keep_fold_edges(std::vector<EdgeRecord>& records);
// A corner of a surface face: its group and node gid (the key), whose it is, the face's reference
// outward normal, and flags: kHasFold in (a fold edge of the face ends there), kFoldVertex and
// kZoneOwner out.
struct VertexRecord {
  static constexpr std::int64_t kHasFold = 1, kFoldVertex = 2, kZoneOwner = 4;
  std::int64_t group, node;
  std::int64_t tet, source, face_corner;  // face_corner = 3·face + corner of the face
  std::int64_t flags;
  double normal[3];
};
// The corners of the given surface faces of `model`'s tets, with the folds among their edges.
std::vector<VertexRecord> vertex_records(const Model& model, const std::vector<FaceRecord>& surface,
                                         const std::vector<EdgeRecord>& folds);
// Sorts the records by key and keeps those at fold vertices, flagged: at each vertex the faces
// are taken in (tet, face_corner) order, each joining the first side whose first face's normal
// lies within kFoldAngleDegrees of its own, or starting a side (and owning it); a side with a
// fold edge at the vertex has a fold vertex there.
void keep_fold_vertices(std::vector<VertexRecord>& records);
// Sets TetArrays::contact_faces (two per local tet, 0 where no record says otherwise) from the
// surface faces, fold edges and fold vertices of the tets held here.
void set_contact_faces(Model& model, const std::vector<FaceRecord>& surface,
                       const std::vector<EdgeRecord>& folds,
                       const std::vector<VertexRecord>& owners);

// One rank or the whole model: sets model.tets.contact_faces for every tet.
void compute_contact_faces(Model& model);

}  // namespace fdem
