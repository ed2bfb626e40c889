// The scene as the user described it (after validation): plain data, SI units.
// io/scene_reader fills it from YAML; drivers/ turn it into a Model.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/materials.hpp"
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

struct FractureSpec {
  double tensile_strength = 0.0;    // Pa
  double cohesion = 0.0;            // Pa
  double friction_angle_deg = 0.0;  // degrees
  double energy_I = 0.0;            // J/m^2
  double energy_II = 0.0;           // J/m^2
  double softening_a = 0.63, softening_b = 1.8, softening_c = 6.0;
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

struct MeshSpec {
  enum class Kind { box, file } kind = Kind::box;
  BoxMeshSpec box;
  std::string file;      // resolved path
  std::string physical;  // optional 3D physical group
};

enum class JointPlacement { none, all };

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

// A kinematic load: prescribed velocity on the nodes of some bodies or of a region.  Components
// given as null in the scene stay free (mask).
struct LoadSpec {
  std::vector<int> bodies;  // body indices (empty: use region)
  std::optional<RegionSpec> region;
  Vec3 velocity = Vec3::Zero();  // m/s
  unsigned dof_mask = 7;         // bit k set: component k prescribed
};

struct OutputSpec {
  double every = 0.0;  // s between frames; 0: first and last only
  std::vector<std::string> fields = {"displacement", "velocity", "stress"};
  double checkpoint_every = 0.0;  // s; 0: none
  double energy_every = 0.0;      // s between energy.csv rows; 0: same as frames
};

struct Scene {
  std::string name;
  std::string source_path;  // the YAML file, for messages
  TimeSettings time;
  Vec3 gravity = Vec3::Zero();  // m/s^2
  std::vector<MaterialSpec> materials;
  std::vector<BodySpec> bodies;
  std::vector<InterfaceSpec> interfaces;
  std::vector<LoadSpec> loads;
  OutputSpec output;
  double contact_buffer = -1.0;  // m; < 0: automatic
};

}  // namespace fdem
