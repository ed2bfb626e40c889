// Run-time state of the engine: structure-of-arrays with global ids and [owned | ghost] ranges.
// Physics kernels read and write these flat arrays; nothing here knows about MPI.  Every per-entry
// field is declared once more, with what it takes part in, in core/fields.hpp.
#pragma once

#include <string>
#include <vector>

#include "core/materials.hpp"
#include "core/scene.hpp"
#include "core/types.hpp"

namespace fdem {

// Resizes to exactly n entries: growing a std::vector by resize() may double its capacity (the
// model's arrays are the largest allocations of a rank; a halo appended to a block would keep
// twice the block's memory reserved).
template <class T, class... Fill>
void resize_exact(std::vector<T>& values, std::size_t n, const Fill&... fill) {
  if (n > values.capacity()) values.reserve(n);
  values.resize(n, fill...);
}

// Nodes.  Vector quantities are stored xyz-interleaved (3 doubles per node) in separate arrays.
struct NodeArrays {
  LocalIndex n_owned = 0;  // entries [0, n_owned) are integrated here; the rest are halo copies
  // False when no node moves at a prescribed nonzero velocity (the scene has no velocity or
  // base-motion load): `prescribed_velocity` then stays empty and constrained components are held
  // at rest, 24 bytes per node saved.  Set by the builders from the scene, the same on every
  // rank; resize() allocates the array only when true.
  bool has_prescribed_velocity = true;
  std::vector<GlobalId> gid;
  std::vector<double> x;  // current position (m)
  // Reference positions, each distinct one stored once: the nodes a `joints: all` body splits
  // from one mesh node (a node per tet corner there) share an entry, 4 bytes per node instead
  // of 24.  Read them with x0(n).
  std::vector<std::int32_t> reference;      // index into reference_positions
  std::vector<double> reference_positions;  // 3 per distinct reference position (m)
  std::vector<double> v;                    // velocity at the last half step (m/s)
  std::vector<double> f;                    // total force at the current step (N)
  std::vector<double> mass;                 // lumped mass (kg)
  std::vector<std::int32_t> piece;          // discrete element (connected piece at t = 0) index
  std::vector<std::uint8_t> constrained;    // bit k: velocity component k is prescribed
  std::vector<double> prescribed_velocity;  // 3 per node (m/s), used where constrained; see above

  LocalIndex size() const { return static_cast<LocalIndex>(gid.size()); }
  void resize(LocalIndex n);
  // Reference position of node n (m).
  Eigen::Map<const Vec3> x0(LocalIndex n) const {
    return vec3_at(reference_positions.data(), reference[static_cast<std::size_t>(n)]);
  }
  // Node n's reference position appended to the table (no search: compact_references merges
  // equal ones afterwards).
  void add_reference(LocalIndex n, const double* position);
  // The table reduced to the distinct positions the nodes use (equal bits merge), in order of
  // first use; the nodes' indices follow.
  void compact_references();
  // Component i (3 per node) of the prescribed velocity: 0 without the array.
  double prescribed_velocity_at(std::size_t i) const {
    return prescribed_velocity.empty() ? 0.0 : prescribed_velocity[i];
  }
  // The array allocated (zeros) if absent: for drivers that set velocities themselves on one rank
  // (tests driving a body).
  void keep_prescribed_velocities() {
    has_prescribed_velocity = true;
    if (prescribed_velocity.empty()) prescribed_velocity.assign(3 * gid.size(), 0.0);
  }
  // Local index of the node with global id `gid` (the owned and the ghost range are each in
  // ascending gid), or −1 when it is not held here.
  LocalIndex find(GlobalId gid) const;
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
  // Mass (kg) the contact dashpot sizes itself by: the tet's piece (a block moves as one).  0:
  // the tet's own mass — a tet of a `joints: all` body (its fragments are not known before they
  // break), or a model assembled by hand.
  std::vector<double> dashpot_mass;
  // Contact group: tets of one group never contact each other.  A body without joints is one
  // group per piece; in a body with `joints: all` every tet is its own group (its neighbours are
  // held by joints, and become contact partners when those break).  Empty: the piece is the group
  // (models assembled by hand); resize() keeps it empty.
  std::vector<std::int32_t> contact_group;
  // Corner contact (contact.formulation: corners) only, else empty: 2 per tet, which faces of the
  // tet lie on its contact group's surface, their folds and fold vertices (core/contact_faces.hpp).
  std::vector<std::int32_t> contact_faces;
  // Start-up only (build_model): 1 for a tet of a `joints: all` body none of whose corners lies on
  // the body mesh's boundary — while that body's joints hold nothing can reach it, so the contact
  // stage leaves it out (docs/contact-detection.md, "Enclosed tets").  The contact stage's joint
  // state carries it from then on.  Empty: none (models assembled by hand).  Not touched by
  // resize().
  std::vector<std::uint8_t> enclosed;
  // Parallel roles (docs/parallel.md).  Local tets are always in ascending gid.  `owned`: this
  // rank owns the tet (reports its energies, writes it in frames and checkpoints); `active`: the
  // tet touches a node this rank owns, or is owned, so this rank computes its forces.  Empty: every
  // tet is owned and active (one rank).  Not touched by resize().
  std::vector<std::uint8_t> owned, active;

  LocalIndex size() const { return static_cast<LocalIndex>(gid.size()); }
  void resize(LocalIndex n);
  // Local index of the tet with global id `gid` (local tets are in ascending gid), or −1.
  LocalIndex find(GlobalId gid) const;
  bool is_owned(LocalIndex t) const { return owned.empty() || owned[t]; }
  bool is_active(LocalIndex t) const { return active.empty() || active[t]; }
  std::int32_t group_of(LocalIndex t) const {
    return contact_group.empty() ? piece[t] : contact_group[t];
  }
};

// What the builder resolved for one cohesive law (fracture/ turns it into a CohesiveLaw).
struct JointLawSpec {
  FractureSpec fracture;            // strengths, energies, softening (scene `fracture:` block)
  double normal_penalty = 0.0;      // p_n (Pa): joint normal stiffness p_n/h (Pa/m)
  double tangential_penalty = 0.0;  // p_t (Pa)
  double element_size = 0.0;        // h (m)
  std::string origin;               // "material 'rock'" or "interface 'a'-'b'", for messages
  double auto_penalty = 0.0;        // Pa: what `penalty: auto` gives this group (50 E)
  // Factor on the block's tensile strength and cohesion of the joints of this law (1: a
  // homogeneous block; else the centre of a strength bin, core/joint_strength).
  double strength_scale = 1.0;
};

// Cohesive joints (docs/fracture-model.md): 6-node elements bonding face (a0, a1, a2) of tet A to
// the coincident face (b0, b1, b2) of tet B; (a1 − a0) × (a2 − a0) points from A into B at t = 0.
// Stored in ascending (gid of A, gid of B) with gid(A) < gid(B); the joint gid is that rank.
// The cohesive history of each integration point lives in the fracture stage; the arrays below
// hold what the rest of the engine reads (output, contact hand-over, fragments).
struct JointArrays {
  std::vector<GlobalId> gid;
  std::vector<LocalIndex> nodes;     // 6 per joint: a0 a1 a2 b0 b1 b2
  std::vector<LocalIndex> tets;      // 2 per joint: A, B
  std::vector<double> area0;         // reference face area (m^2)
  std::vector<std::int32_t> law;     // index into Model::joint_laws
  std::vector<std::uint8_t> broken;  // 1 once all three points reached D = 1
  std::vector<std::uint8_t> mode;    // FailureMode code (fracture/joint_kernels.hpp), 0 intact
  // A joint's damage and failure time live in the joint stage's history, which only joints that
  // left the pristine state keep (fracture/joint_stage.hpp: JointStage::damage, failure_time).

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

// The discrete elements, numbered body by body: a piece's id is its body's first id plus its index
// in the body, so its body and index follow from one number per body.  Mass and reference
// centroid are *kept* for some pieces only: every piece in one process; on N ranks those of the
// rank's directory block of ids (parallel/piece_directory), so no rank holds a table of every
// piece of a wall of 10^6 blocks.
class PieceTable {
 public:
  void add_body(std::int32_t pieces);  // the pieces of the next body
  std::size_t size() const { return static_cast<std::size_t>(first_.back()); }  // whole model
  std::int32_t bodies() const { return static_cast<std::int32_t>(first_.size()) - 1; }
  std::int32_t first_of_body(std::int32_t body) const { return first_[body]; }
  std::int32_t pieces_in_body(std::int32_t body) const { return first_[body + 1] - first_[body]; }
  std::int32_t body_of(std::int32_t piece) const;
  std::int32_t index_in_body(std::int32_t piece) const { return piece - first_[body_of(piece)]; }

  // Kept pieces, in ascending id; added ones start with mass 0.
  const std::vector<std::int32_t>& kept() const { return kept_id_; }
  bool keeps(std::int32_t piece) const { return slot(piece) >= 0; }
  void keep_all() { keep_range(0, static_cast<std::int32_t>(size())); }
  void keep_range(std::int32_t begin, std::int32_t end);
  void keep(const std::vector<std::int32_t>& sorted_ids);
  void keep_only_range(std::int32_t begin, std::int32_t end);  // drops the others
  PieceInfo& operator[](std::int32_t piece);
  const PieceInfo& operator[](std::int32_t piece) const;

 private:
  std::int32_t slot(std::int32_t piece) const;  // index into kept_, or −1

  std::vector<std::int32_t> first_{0};  // per body its first id, then the total
  std::vector<std::int32_t> kept_id_;
  std::vector<PieceInfo> kept_;
};

struct Model {
  NodeArrays nodes;
  TetArrays tets;
  std::vector<MaterialProperties> materials;
  PieceTable pieces;
  std::vector<std::string> body_names;
  std::vector<bool> body_fixed;
  // Local active tets in ascending global id: the order in which element forces are added to
  // nodes, so a node's force is the same sum in the same order on any rank and in any layout.
  std::vector<LocalIndex> tet_force_order;
  Vec3 gravity = Vec3::Zero();
  JointArrays joints;
  std::vector<JointLawSpec> joint_laws;
  // Node, tet and joint gids are gid_offset + their index 0..N−1 in the whole model (scene key
  // parallel.gid_offset, a testing aid).  Whatever maps a gid to a dense position — directories,
  // checkpoint rows, hashes — uses gid − gid_offset.
  GlobalId gid_offset = 0;
};

// `n` (how many nodes, tets or joints — `what` — one rank is to hold) as a LocalIndex; throws
// InputError when it exceeds max_local_entries, before any array of that size is indexed.
LocalIndex local_count(std::size_t n, const char* what);

// Builds tet_force_order from the tets' global ids (call after any change of the tet arrays).
void build_tet_force_order(const TetArrays& tets, std::vector<LocalIndex>& order);

// Whether bodies can come into contact at all: at least two pieces (or a jointed body's contact
// groups, which meet once its joints break), not all of them fixed.
bool contact_possible(const Model& model);

// Discrete elements now: connected components of tets linked by a shared node or an intact
// joint.  At t = 0 with intact joints this equals the number of pieces.
std::int32_t count_fragments(const Model& model);

}  // namespace fdem
