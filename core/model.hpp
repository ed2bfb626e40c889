// Run-time state of the engine: structure-of-arrays with global ids and [owned | ghost] ranges.
// Physics kernels read and write these flat arrays; nothing here knows about MPI.
#pragma once

#include <string>
#include <vector>

#include "core/materials.hpp"
#include "core/scene.hpp"
#include "core/types.hpp"

namespace fdem {

// Nodes.  Vector quantities are stored xyz-interleaved (3 doubles per node) in separate arrays.
struct NodeArrays {
  LocalIndex n_owned = 0;  // entries [0, n_owned) are integrated here; the rest are halo copies
  std::vector<GlobalId> gid;
  std::vector<double> x;                    // current position (m)
  std::vector<double> x0;                   // reference position (m)
  std::vector<double> v;                    // velocity at the last half step (m/s)
  std::vector<double> f;                    // total force at the current step (N)
  std::vector<double> mass;                 // lumped mass (kg)
  std::vector<std::int32_t> piece;          // discrete element (connected piece at t = 0) index
  std::vector<std::uint8_t> constrained;    // bit k: velocity component k is prescribed
  std::vector<double> prescribed_velocity;  // 3 per node (m/s), used where constrained

  LocalIndex size() const { return static_cast<LocalIndex>(gid.size()); }
  void resize(LocalIndex n);
};

// Linear tetrahedra.
struct TetArrays {
  LocalIndex n_owned = 0;
  std::vector<GlobalId> gid;
  std::vector<LocalIndex> nodes;  // 4 per tet
  std::vector<double> dm_inv;     // 9 per tet, column-major inverse reference edge matrix (1/m)
  std::vector<double> volume0;    // reference volume (m^3)
  std::vector<std::int32_t> material;
  std::vector<std::int32_t> piece;
  std::vector<double> viscosity;  // Pa·s (0: undamped)

  LocalIndex size() const { return static_cast<LocalIndex>(gid.size()); }
  void resize(LocalIndex n);
};

// Material constants resolved for the kernels.
struct MaterialProperties {
  std::string name;
  double density = 0.0;
  ElasticModel model = ElasticModel::neo_hookean;
  LameParameters lame;
  double young = 0.0, poisson = 0.0;
  double damping_ratio = 0.0;
  ContactSpec contact;
};

// A discrete element: a connected piece of one body's mesh at t = 0.
struct PieceInfo {
  std::int32_t body = -1;  // index into Scene::bodies
  std::int32_t index_in_body = 0;
  double mass = 0.0;              // kg
  Vec3 centroid0 = Vec3::Zero();  // mass-weighted reference centroid (m)
};

// Compressed rows: for each node, the (tet, corner) slots that put force on it, in ascending
// tet global id.  Gathering in this order makes force sums independent of loop order and rank.
struct NodeCornerMap {
  std::vector<LocalIndex> offsets;  // n_nodes + 1
  std::vector<LocalIndex> slots;    // 4*tet + corner
};

struct Model {
  NodeArrays nodes;
  TetArrays tets;
  std::vector<MaterialProperties> materials;
  std::vector<PieceInfo> pieces;
  std::vector<std::string> body_names;
  std::vector<bool> body_fixed;
  NodeCornerMap node_corners;
  Vec3 gravity = Vec3::Zero();
};

// Builds node_corners from tets (call after any change of the tet arrays).
void build_node_corner_map(const TetArrays& tets, LocalIndex n_nodes, NodeCornerMap& map);

}  // namespace fdem
