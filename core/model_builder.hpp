// Turns a validated Scene plus one tetrahedral mesh per body into the run-time Model:
// connected pieces, space-filling-curve element order, global ids, lumped masses, reference
// shapes, initial velocities and kinematic constraints.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/model.hpp"
#include "core/scene.hpp"

namespace fdem {

// A body's mesh before it joins the model.
struct BodyMesh {
  std::vector<double> coords;             // 3 per node (m)
  std::vector<LocalIndex> tets;           // 4 per tet, 0-based
  std::vector<std::int64_t> source_tags;  // element tag in the source file (for messages), or empty
  std::string source;                     // "box generator", a file name, ...
};

// A part of a body's mesh generated on its own (distributed start-up, parallel/distributed_build):
// local node numbers, each with its number in the whole body mesh, and tets with their number in
// the whole mesh and the same corners in the same order, so the chunks of a body together give
// exactly the mesh the whole generator gives.
struct MeshChunk {
  BodyMesh mesh;
  std::vector<std::int64_t> node_id;    // per chunk node: its number in the whole body mesh
  std::vector<std::int64_t> tet_id;     // per chunk tet: its number in the whole body mesh
  std::int32_t piece = 0;               // the connected piece of the body the chunk lies in
  std::vector<std::int32_t> tet_piece;  // per chunk tet, when the chunk spans several pieces
                                        // (empty: every tet is in `piece`)
};

// How a body's mesh splits into chunks, without generating it.
struct BodyChunks {
  std::int64_t n_nodes = 0;              // nodes of the whole body mesh
  std::int32_t n_pieces = 0;             // connected pieces (numbered as connected_pieces does)
  std::vector<std::int64_t> chunk_tets;  // tets of each chunk
  std::vector<Vec3> chunk_centre;        // a point near each chunk's middle (m), to deal chunks
                                         // to ranks along a space-filling curve
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // box of the body's nodes (m; for curved units
                                              // that of their corners)
  std::string source;                         // the whole mesh's BodyMesh::source (for messages)
  // Empty: chunks are dealt to ranks along a space-filling curve.  Else chunk c is generated on
  // rank chunk_rank[c] (a plan made on the ranks already: slices of a model file).
  std::vector<int> chunk_rank;
  std::function<MeshChunk(std::int64_t chunk)> generate;
};

// Connected pieces of a tet mesh (tets sharing a node belong together): piece index per tet.
std::vector<std::int32_t> connected_pieces(const std::vector<LocalIndex>& tets, LocalIndex n_nodes,
                                           std::int32_t* n_pieces);

// 63-bit Morton key of a point inside the box [lo, hi]: 21 bits on the longest axis, one bit fewer
// on another axis per halving of its extent against the longest (cells about cubes).
std::uint64_t morton_key(const Vec3& p, const Vec3& lo, const Vec3& hi);

// Throws InputError naming the body, its source and the tet's number (`tag`) if the tet with
// corners X is inverted or degenerate.
void check_tet_shape(const Vec3 (&X)[4], const std::string& body, const std::string& source,
                     std::int64_t tag);

// What a tet's reference shape and material give: Dm⁻¹ (1/m), volume (m³), mass (kg) and the
// viscosity (Pa·s) that damps its highest mode by the material's ratio (0 without damping).
struct TetSetup {
  Mat3 dm_inv;
  double volume = 0.0, mass = 0.0, viscosity = 0.0;
};
TetSetup setup_tet(const Vec3 (&X)[4], const MaterialProperties& material);

// Piece mass and centroid, summed tet by tet in ascending tet gid (the order fixes the rounding),
// then finished (centroid = Σ m·c / Σ m).
void add_to_piece(PieceInfo& piece, double element_mass, const Vec3 (&X)[4]);
void finish_piece(PieceInfo& piece);

// Each tet's dashpot mass (TetArrays::dashpot_mass): its piece's mass, or 0 (the tet's own) in a
// `joints: all` body (its contact group is not its piece).  The pieces of the tets must be kept.
void set_dashpot_masses(Model& model);

// Initial velocity of every node: its body's translation plus rotation about its piece's own
// reference centroid.
void set_initial_velocities(const Scene& scene, Model& model);

// A model with the scene's materials, body names, fixed flags and gravity, and no mesh yet.
Model model_frame(const Scene& scene);

enum class ElementOrder { space_filling_curve, as_given };

Model build_model(const Scene& scene, const std::vector<BodyMesh>& meshes,
                  ElementOrder order = ElementOrder::space_filling_curve);

// Applies fixed bodies and kinematic loads to the nodes' constraint masks.
void apply_constraints(const Scene& scene, Model& model);

// Whether a reference position lies in a load's region (its box, faces included).
inline bool in_region(const RegionSpec& region, const Vec3& X) {
  return (X.array() >= region.min.array()).all() && (X.array() <= region.max.array()).all();
}
// The owned nodes whose reference position lies in the region.
std::int64_t owned_nodes_in_region(const RegionSpec& region, const NodeArrays& nodes);
}  // namespace fdem
