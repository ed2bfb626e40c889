// Cohesive joint placement of build_model (core/model_builder), and the pieces of it the
// distributed start-up (parallel/distributed_joints) shares, so that both place the same joints
// with the same bits: geometry, size bins, laws, tolerance cells and messages.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/model.hpp"
#include "core/model_builder.hpp"
#include "core/scene.hpp"

namespace fdem {

// Places the cohesive joints of `joints: all` bodies (every interior face), `joints: interfaces`
// bodies (boundary faces of one piece coinciding with a boundary face of another) and
// `interfaces:` (boundary faces of body A coinciding with boundary faces of body B at t = 0),
// resolves their laws, and stores them in model.joints in canonical order.  `model_tet[b][t]`:
// the model tet of body b's mesh tet t; `extent`: of the box of all nodes (m).  Throws
// InputError for a non-manifold mesh and for touching pieces or interfaces without a match.
void place_joints(const Scene& scene, const std::vector<BodyMesh>& meshes,
                  const std::vector<std::vector<LocalIndex>>& model_tet, const Vec3& extent,
                  Model& model);

// Touching pieces and interfaces match node positions within this distance (m): 1e-9 of the
// extent of the box of all nodes.
double matching_tolerance(const Vec3& extent);
// The cell of a hash grid of spacing `tol` (m) that holds x; two nodes within tol lie in cells
// at most one apart along each axis.  A coordinate so far from the origin that x / tol leaves the
// 64-bit range cannot be matched to a neighbour's: InputError.
std::array<std::int64_t, 3> tolerance_cell(const Vec3& x, double tol);

// Whether the face (a0, a1, a2) of tet A must be turned (a1 ↔ a2, and b1 ↔ b2 on the other side)
// so that (a1 − a0) × (a2 − a0) points away from A's fourth corner `opposite`.
bool joint_face_turned(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& opposite);
// Area (m²) of the joint face as oriented.
double joint_face_area(const Vec3& a0, const Vec3& a1, const Vec3& a2);
// Element-size bin of a joint: h = mean of the two tets' altitudes onto the face (volumes m³,
// area m²), binned by a ratio of 1.02.
long joint_size_bin(double volume_a, double volume_b, double area);

// What names a law: the joint group (material index, or materials + interface index), the
// element-size bin and the strength bin (core/joint_strength; 0 without a strength
// distribution).  Laws are numbered in ascending key over the keys the model's joints use — not
// in order of appearance — so that any placement order, and any rank count, numbers them alike.
struct JointLawKey {
  std::int64_t group = 0, size_bin = 0, strength_bin = 0;
  bool operator<(const JointLawKey& o) const {
    if (group != o.group) return group < o.group;
    return size_bin != o.size_bin ? size_bin < o.size_bin : strength_bin < o.strength_bin;
  }
  bool operator==(const JointLawKey& o) const {
    return group == o.group && size_bin == o.size_bin && strength_bin == o.strength_bin;
  }
};
// The fracture block of a joint group.
const FractureSpec& group_fracture(const Scene& scene, std::int64_t group);
// The strength bin of the joint with gid `gid` in `group` (keyed by gid − gid_offset).
long joint_strength_bin(const Scene& scene, std::int64_t group, GlobalId gid, GlobalId gid_offset);
// The law of a key: the block's values, its penalties (auto: 50 E; an interface: of the smaller
// E), the bin's element size and strength factor.
JointLawSpec joint_law(const Scene& scene, const JointLawKey& key);

// The builders' messages for a mesh joints cannot be placed on (mesh nodes 0-based).
std::string non_manifold_message(const std::string& body, const std::string& source,
                                 const std::array<std::int64_t, 3>& mesh_nodes);
std::string no_touching_pieces_message(const Scene& scene, std::size_t body,
                                       const std::string& source);
std::string no_interface_match_message(const Scene& scene, std::size_t interface, double tol);

}  // namespace fdem
