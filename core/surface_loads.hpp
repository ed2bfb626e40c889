// Pressure and traction on boundary faces (scene loads with `pressure` or `traction`): which
// faces a load acts on, and the per-face kernels.  A boundary face is a tet face that no other
// tet shares and that is not a cohesive joint's face; a face is kept when it has an owned node,
// so on N ranks every tet and joint on it is held here (each owned node's tets and joints are)
// and the choice is the same as on one rank.  Faces are kept in ascending (tet gid, face), the
// order in which their forces are added to the nodes: a node's sum is the same on any rank count.
#pragma once

#include <cstdint>
#include <vector>

#include "core/model.hpp"
#include "core/scene.hpp"

namespace fdem {

// Corners of the face opposite corner c of a tet, in the order whose (x1 − x0) × (x2 − x0)
// points out of a positively oriented tet.
constexpr int tet_face_corners[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

// Force (N) on each corner of a triangle x0 x1 x2 (outward order) under pressure p (Pa, > 0
// pushes inwards): −p·a/3 with a = ½(x1 − x0) × (x2 − x0) its area vector — exact for a flat
// linear triangle (∫ N_i dA = A/3).
inline Vec3 pressure_corner_force(const Vec3& x0, const Vec3& x1, const Vec3& x2, double p) {
  return (-p / 6.0) * (x1 - x0).cross(x2 - x0);
}

// Force (N) on each corner of a triangle under a traction t (Pa) on its area: t·|a|/3.
inline Vec3 traction_corner_force(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& t) {
  return (0.5 * (x1 - x0).cross(x2 - x0).norm() / 3.0) * t;
}

// The faces of one surface load on this process.
struct SurfaceFaces {
  std::vector<LocalIndex> nodes;     // 3 per face, outward order
  std::vector<GlobalId> tet;         // gid of the face's tet
  std::vector<std::uint8_t> owned;   // 1: the face's tet is owned here (counts it once)
  std::vector<double> corner_force;  // 3 per face (N), set by add_surface_forces

  LocalIndex size() const { return static_cast<LocalIndex>(tet.size()); }
};

// The boundary faces `load` acts on: of its bodies, or with three corners in its region at t = 0.
SurfaceFaces select_surface_faces(const Model& model, const LoadSpec& load);

// Sets each face's corner force for the load's magnitude × `factor` (its history at this time)
// and adds it to the force of the face's three nodes, face by face.  A follower pressure uses
// the current positions x, a fixed one and a traction the reference positions x0.
void add_surface_forces(const SurfaceLoadSpec& spec, double factor, SurfaceFaces& faces,
                        NodeArrays& nodes);

// Σ |corner force| over the corners of the faces owned here (N): the loads' size, for the
// unbalanced-force ratio of quasi-static runs.
double surface_force_magnitude(const SurfaceFaces& faces);

// Σ corner force · v over the corners at owned nodes (W), with the nodes' current velocities.
double surface_power(const SurfaceFaces& faces, const NodeArrays& nodes);

// Σ of the corner forces of faces whose tet is owned here (N): the load's resultant.
Vec3 surface_resultant(const SurfaceFaces& faces);

}  // namespace fdem
