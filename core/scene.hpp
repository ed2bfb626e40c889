// The scene as the user described it (after validation): plain data, SI units.
// io/scene_reader fills it from YAML; drivers/ turn it into a Model.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/materials.hpp"
#include "core/time_history.hpp"
#include "core/types.hpp"

namespace fdem {

struct TimeSettings {
  double end = 0.0;  // simulated seconds
  bool auto_step = true;
  double step = 0.0;    // s, when not automatic
  double safety = 0.7;  // fraction of the critical step used when automatic
};

struct ElasticSpec {
  ElasticModel model = ElasticModel::neo_hookean;
  double young = 0.0;    // Pa
  double poisson = 0.0;  // −
};

struct ContactSpec {
  bool auto_penalty = true;
  double penalty = 0.0;   // Pa, when not automatic
  double friction = 0.0;  // Coulomb coefficient μ
  double damping = 0.0;   // normal viscous damping ratio of a contact pair (fraction of critical)
};

// Spread of joint strength: each joint's tensile strength and cohesion are the block's values
// times a factor drawn from this distribution by a hash of (seed, joint gid), so the draw does
// not depend on ranks or on the order joints are found in (core/joint_strength).
struct StrengthDistributionSpec {
  enum class Type { none, weibull, normal } type = Type::none;
  double modulus = 0.0;    // Weibull modulus m (> 0): scatter falls as m grows
  double cov = 0.0;        // normal: coefficient of variation (standard deviation / mean)
  std::uint64_t seed = 0;  // any integer; another seed gives another realisation
};

struct FractureSpec {
  double tensile_strength = 0.0;    // Pa
  double cohesion = 0.0;            // Pa
  double friction_angle_deg = 0.0;  // degrees
  double energy_I = 0.0;            // J/m^2
  double energy_II = 0.0;           // J/m^2
  double softening_a = 0.63, softening_b = 1.8, softening_c = 6.0;
  // Joint penalties p_n, p_t (Pa): the joint layer's stiffness is p/h.  0: auto (50 E).
  double normal_penalty = 0.0, tangential_penalty = 0.0;
  StrengthDistributionSpec strength_distribution;
  // Where the block is, for messages raised after reading: its key path
  // ("materials.rock.fracture") and "file:line" (or the file).
  std::string key, location;
};

struct MaterialSpec {
  std::string name;
  double density = 0.0;  // kg/m^3
  ElasticSpec elastic;
  double damping = 0.0;  // viscous damping ratio of each element's highest mode
  ContactSpec contact;
  std::optional<FractureSpec> fracture;
};

struct BoxMeshSpec {
  Vec3 min = Vec3::Zero(), max = Vec3::Zero();
  int cells[3] = {1, 1, 1};
};

// A wall of rectangular units (bricks, stones) in courses; each unit is its own piece.  Units lie
// along x, the wall's thickness is y, courses are stacked along z from `origin` (smallest x, y, z).
struct WallMeshSpec {
  enum class Bond { stack, running } bond = Bond::stack;
  Vec3 unit = Vec3::Zero();    // unit size lx (along the wall), ly (thickness), lz (height), m
  int courses = 1;             // number of courses (rows)
  int units_per_course = 1;    // full units per course (running bond: n − 1 full + 2 half units)
  double mortar_gap = 0.0;     // m between neighbouring units (head and bed joints)
  int cells[3] = {2, 1, 1};    // box cells per full unit (running bond: cells[0] even)
  Vec3 origin = Vec3::Zero();  // m
};

// An arch in the x–z plane (depth along y) of curved-wedge voussoirs with radial joints.  The
// intrados circle has radius `radius` about `origin`; the arch spans y in [origin.y, + depth].
struct ArchMeshSpec {
  enum class Kind { semicircular, segmental } kind = Kind::semicircular;
  double radius = 0.0;     // intrados radius (m)
  double thickness = 0.0;  // radial (m)
  double depth = 0.0;      // along y (m)
  int voussoirs = 1;
  double half_angle = M_PI / 2;  // rad: half the angle the arch subtends (semicircular: π/2)
  bool abutments = false;        // a block under each springing
  double abutment_width = 0.0;   // m along x at the foot, from the intrados springing point
  double abutment_height = 0.0;  // m below the lower springing corner
  int cells[3] = {2, 2, 1};      // per voussoir: radial, along the arc, depth
  Vec3 origin = Vec3::Zero();    // centre of the intrados circle (m)
};

// A pier of `blocks` equal blocks stacked along z from `origin` (smallest x, y, z).
struct TowerMeshSpec {
  Vec3 block = Vec3::Zero();  // m
  int blocks = 1;
  int cells[3] = {2, 2, 2};  // box cells per block
  Vec3 origin = Vec3::Zero();
};

struct MeshSpec {
  enum class Kind { box, file, wall, arch, tower } kind = Kind::box;
  BoxMeshSpec box;
  std::string file;      // resolved path
  std::string physical;  // optional 3D physical group
  WallMeshSpec wall;
  ArchMeshSpec arch;
  TowerMeshSpec tower;
};

// none; all: every interior face of the mesh; interfaces: faces where different pieces of the
// body touch at t = 0 (mortar between the units of a generated wall), law = the material's
// fracture.
enum class JointPlacement { none, all, interfaces };

struct BodySpec {
  std::string name;
  MeshSpec mesh;
  int material = -1;  // index into Scene::materials
  bool fixed = false;
  JointPlacement joints = JointPlacement::none;
  Vec3 velocity = Vec3::Zero();          // m/s
  Vec3 angular_velocity = Vec3::Zero();  // rad/s, about each piece's centroid
};

struct InterfaceSpec {
  int body_a = -1, body_b = -1;
  FractureSpec fracture;
};

struct RegionSpec {
  Vec3 min = Vec3::Zero(), max = Vec3::Zero();  // axis-aligned box (m), nodes inside at t = 0
};

// A viscous absorbing boundary (core/absorbing_boundary): the mesh's boundary faces whose three
// nodes lie in `region` at t = 0, of the listed bodies (empty: any body).
struct AbsorbingSpec {
  RegionSpec region;
  std::vector<int> bodies;
};

// Initial (in-situ) stress of the tets (core/initial_stress), Cauchy, tension positive (Pa).
// uniform: `stress` everywhere; geostatic: σ_v = −ρ·|g|·depth along gravity below `surface` (the
// height of the free surface along −g, m) and σ_h = K0·σ_v across it.
struct InitialStressSpec {
  enum class Kind { none, uniform, geostatic } kind = Kind::none;
  double stress[6] = {0, 0, 0, 0, 0, 0};  // uniform: xx, yy, zz, yz, xz, xy (Pa)
  double surface = 0.0;                   // geostatic: height of the free surface (m)
  double k0 = 1.0;                        // geostatic: σ_h / σ_v
  std::vector<int> bodies;                // empty: every body
};

// Ground acceleration record a(t) (m/s² after `scale`), linear between samples, zero outside.
struct BaseMotionSpec {
  std::string file;                  // resolved CSV path ("" when given in code)
  std::vector<double> time;          // s, increasing (read from `file` when empty)
  std::vector<double> acceleration;  // record units; × scale gives m/s²
  Vec3 direction = Vec3::UnitX();    // unit vector
  double scale = 1.0;
};

// Tilting table: gravity turns about `axis` (right hand) by rate·(t − start), at most `max`.
struct TiltSpec {
  Vec3 axis = Vec3::UnitY();  // unit vector
  double rate = 0.0;          // rad/s
  double max = 0.0;           // rad
  double start = 0.0;         // s
};

// Uniform horizontal acceleration added to gravity: direction·min(rate·(t − start), max), or
// direction·history(t) when a history is given instead of rate and max.
struct RampSpec {
  Vec3 direction = Vec3::UnitX();      // unit vector
  double rate = 0.0;                   // m/s³
  double max = 0.0;                    // m/s²
  double start = 0.0;                  // s
  std::optional<TimeHistory> history;  // m/s²
};

// A pressure or traction on the boundary faces of a region (faces whose three corners lie in
// the box at t = 0) or of bodies (all their boundary faces).  Boundary faces belong to one tet
// and are not a joint's face.  Pressure p pushes along the inward normal: with `follower` the
// force is −p·a on the current area vector a (finite strain, rotating faces), else −p·A on the
// reference one.  Traction t (Pa, fixed direction) gives t·A on the reference area.  Either is
// multiplied by LoadSpec::history(t).
struct SurfaceLoadSpec {
  enum class Kind { pressure, traction } kind = Kind::pressure;
  double pressure = 0.0;         // Pa, > 0 compresses
  Vec3 traction = Vec3::Zero();  // Pa
  bool follower = true;          // pressure only
  // A Gmsh physical surface of the (one) body's mesh file: only faces that coincide with one of
  // its triangles (9 coordinates each, m) are loaded.  Empty: every boundary face of the bodies.
  std::string physical;
  std::vector<double> triangles;
};

// A load: prescribed velocity on the nodes of some bodies or of a region (components given as
// null in the scene stay free: mask), a base motion of some bodies, or a time-varying gravity.
struct LoadSpec {
  enum class Kind { velocity, base_motion, tilt, ramp, surface } kind = Kind::velocity;
  std::string name;         // for output.histories columns (default load<index in the list>)
  std::vector<int> bodies;  // body indices (empty: use region)
  std::optional<RegionSpec> region;
  Vec3 velocity = Vec3::Zero();  // m/s, × history(t)
  unsigned dof_mask = 7;         // bit k set: component k prescribed
  TimeHistory history;           // velocity and surface loads: factor of the magnitude (1)
  BaseMotionSpec base_motion;    // kind == base_motion (all components prescribed)
  TiltSpec tilt;                 // kind == tilt
  RampSpec ramp;                 // kind == ramp
  SurfaceLoadSpec surface;       // kind == surface (bodies or region select the faces)
  std::string where;             // "FILE:LINE:COLUMN: loads[i].region" (or .bodies), for messages

  // A velocity or base-motion load: it prescribes its nodes' velocities (the others hold none).
  bool prescribes_velocity() const { return kind == Kind::velocity || kind == Kind::base_motion; }
};

// A point whose displacement, velocity and stress histories.csv records, interpolated in the tet
// that holds it at t = 0.
struct MonitorSpec {
  std::string name;
  Vec3 point = Vec3::Zero();  // m, reference configuration
  std::string where;          // "FILE:LINE:COLUMN: output.histories.monitors[i]", for messages
  // m: the run ends at the first row of histories.csv where the point has moved this far (a
  // collapse, or a pushover's target); 0: never.
  double stop_displacement = 0.0;
};

// output.histories: rows of histories.csv (drivers/histories).  Loads: reaction and mean
// displacement of a prescribed-velocity or base-motion load; bodies: mean displacement and
// resultant force; monitors: values at a point.
struct HistoriesSpec {
  bool enabled = false;
  double every = -1.0;     // s between rows; 0: every step; < 0: the energy.csv interval
  std::vector<int> loads;  // indices into Scene::loads (velocity and base-motion loads only)
  std::vector<int> bodies;
  std::vector<MonitorSpec> monitors;
  // A monitor ends the run at its stop_displacement: rows are taken even without output files.
  bool stops_runs() const {
    for (const MonitorSpec& m : monitors)
      if (m.stop_displacement > 0.0) return true;
    return false;
  }
};

struct OutputSpec {
  double every = 0.0;  // s between frames; 0: first and last only
  std::vector<std::string> fields = {"displacement", "velocity", "stress"};
  double checkpoint_every = 0.0;  // s; 0: none
  double energy_every = 0.0;      // s between energy.csv rows; 0: same as frames
  // Tet frames: vtu = a .vtu per rank and a .pvtu per frame (frames.pvd); xdmf = one HDF5 file
  // per frame written collectively by every rank, listed in frames.xdmf (docs/parallel.md,
  // "Frames at scale").  vtu stays the default; xdmf is the one to use on many ranks.
  enum class FrameFormat { vtu, xdmf } format = FrameFormat::vtu;
  // MPI-IO hints (MPI_Info key/value, e.g. striping_factor = 16) for the xdmf frames' HDF5 files;
  // the FDEM_MPIIO_HINTS environment variable adds to and overrides these.
  std::vector<std::pair<std::string, std::string>> mpi_io_hints;
  HistoriesSpec histories;
};

// Parallel runs (docs/parallel.md): when the decomposition is revisited.
struct ParallelSpec {
  double rebalance_threshold = 1.10;  // re-partition when max/mean owned cost exceeds this
  long redistribute_every = 0;        // steps; also redistribute this often (0: at detections only)
  // N ranks, scenes without joints: each rank builds only its part (generated meshes chunk by
  // chunk, Gmsh meshes slice by slice from a model file; false: every rank builds the whole model
  // first, as scenes with joints always do).
  bool distributed_start = true;
  // Re-partition method (Zoltan): rib (inertial bisection), rcb (coordinate bisection), hsfc
  // (Hilbert curve: least data moved while partitioning); random (a test mode: each re-partition
  // scatters the tets to ranks at random — results must not change).
  std::string partitioner = "rib";
  // What a detection cycle sends: incremental (only the copies a rank does not hold yet; every
  // copy afresh when owners move) or full (every copy at every cycle: the reference path).
  std::string migration = "incremental";
  // When to re-partition: measured (when the imbalance exceeds rebalance_threshold and the
  // predicted gain over the next interval — the busiest rank's measured step time above the
  // mean — exceeds the measured cost of the last re-partition) or threshold (whenever the
  // imbalance of the cost weights exceeds rebalance_threshold).
  std::string repartition = "measured";
  // Testing aid: every node, tet and joint gid is this plus its index 0..N−1 (0: gids are the
  // indices), so a small scene runs with gids above 2^32 through every path that handles them.
  // Results and state_hash do not depend on it.  0 <= gid_offset < 2^62.
  std::int64_t gid_offset = 0;
};

// Quasi-static mode (the dynamics are then not physical: only the equilibria and the collapse
// thresholds are).  quasi_static.damping: how it takes the motion out.  local: Cundall's local
// non-viscous damping α·|f| on every free component (3DEC, FLAC); kinetic: every free velocity
// set to 0 each time the kinetic energy passes a peak (kinetic damping, dynamic relaxation), with
// no force taken from a motion that keeps speeding up (a mechanism that forms).
enum class QuasiStaticDamping { local, kinetic };

struct QuasiStaticSpec {
  QuasiStaticDamping damping = QuasiStaticDamping::local;
  double local_damping = 0.0;  // α in [0, 1): the unbalanced force is damped by α·|f|; 0: off
  double until = HUGE_VAL;     // s: dynamic (undamped) from this time on, e.g. after settling
  // > 0: the run ends at the first step (while damped) whose mean unbalanced force is below this
  // fraction of the weight and support forces: Σ|f| over free components / (Σm·|g| + Σ|f| over
  // prescribed ones).  0: runs to time.end.
  double equilibrium_ratio = 0.0;
  bool kinetic() const { return damping == QuasiStaticDamping::kinetic; }
  bool enabled() const { return kinetic() || local_damping > 0.0; }
  bool active_at(double t) const { return enabled() && t < until; }
  bool active_until(double end) const { return enabled() && until >= end; }  // whole run
};

// Ceilings between a valid scene and a runnable one (drivers/run_limits): checked by `fdem check`
// and `run` before the meshes are generated and again on the built model.
struct LimitsSpec {
  double max_steps = 1e8;            // time steps of one run (time.end / time step)
  double max_memory_per_rank = 0.0;  // bytes; 0: automatic (this machine's memory per rank)
};

// contact.formulation: the law between bodies in contact.  potential: Munjiza's potential over
// the tets' overlap; corners: penalty springs at surface faces' corners
// (contact/corner_contact.hpp), which keep an opening hinge's thrust on its edge; automatic:
// corners where they are verified (uses_corner_contact), potential elsewhere.
enum class ContactFormulation { automatic, potential, corners };

struct Scene {
  std::string name;
  std::string source_path;  // the YAML file, for messages
  TimeSettings time;
  Vec3 gravity = Vec3::Zero();  // m/s^2
  std::vector<MaterialSpec> materials;
  std::vector<BodySpec> bodies;
  std::vector<InterfaceSpec> interfaces;
  std::vector<LoadSpec> loads;
  std::vector<AbsorbingSpec> absorbing;  // viscous absorbing boundaries
  std::vector<InitialStressSpec> initial_stress;
  QuasiStaticSpec quasi_static;
  OutputSpec output;
  double contact_buffer = -1.0;         // m; < 0: automatic
  bool contact_skip_enclosed = true;    // contact.skip_enclosed (ContactSettings::skip_enclosed)
  bool contact_exact_narrowing = true;  // contact.narrowing (ContactSettings::exact_narrowing)
  double contact_friction_anchor_lag = 0.05;  // s, contact.friction_anchor_lag
  bool contact_body_dashpot = true;           // contact.dashpot (ContactSettings::body_dashpot)
  double contact_sliver_tolerance = 1e-6;     // contact.sliver_tolerance (ContactSettings)
  bool contact_clip_replay = true;            // contact.clip_replay (ContactSettings)
  ContactFormulation contact_formulation = ContactFormulation::automatic;  // uses_corner_contact
  ParallelSpec parallel;
  LimitsSpec limits;

  // True when a load moves nodes at a prescribed velocity (velocity or base-motion loads); fixed
  // bodies alone hold their nodes at rest and need no stored velocities.
  bool prescribes_velocities() const {
    return std::any_of(loads.begin(), loads.end(),
                       [](const LoadSpec& load) { return load.prescribes_velocity(); });
  }
};

// Whether contact acts at corners (contact.formulation: corners, or auto in a run damped by the
// quasi-static mode throughout, on bodies without joints).  Quasi-static runs ask for collapse
// thresholds, which corner contact gives within 2 % of the rigid-block values at the default
// penalty and potential contact 5–8 % low (an arch's hinges); dynamic runs with blocks tumbling
// across each other, and contact across broken joints, are verified under potential contact
// only (docs/verification.md, "Corner contact").
inline bool uses_corner_contact(const Scene& scene) {
  if (scene.contact_formulation != ContactFormulation::automatic)
    return scene.contact_formulation == ContactFormulation::corners;
  if (!scene.quasi_static.active_until(scene.time.end) || !scene.interfaces.empty()) return false;
  for (const BodySpec& body : scene.bodies)
    if (body.joints != JointPlacement::none) return false;
  return true;
}

}  // namespace fdem
