// Builders for scenes made in code instead of YAML: materials, box bodies, loads, a quiet
// simulation, and what verification problems read back (reactions, broken joints).  Used by the
// verification tests and by the verification benchmark, so both build the same problems.
#pragma once

#include <memory>
#include <string>

#include "core/model_builder.hpp"
#include "drivers/mesh_generators.hpp"
#include "drivers/simulation.hpp"

namespace fdem::builders {

inline MaterialSpec elastic_material(double density, double young, double poisson,
                                     ElasticModel model = ElasticModel::neo_hookean) {
  MaterialSpec m;
  m.name = "material";
  m.density = density;
  m.elastic.model = model;
  m.elastic.young = young;
  m.elastic.poisson = poisson;
  return m;
}

// Cohesive joint parameters: strengths (Pa), friction angle (degrees), fracture energies (J/m²).
// The defaults are a weak rock's joints, as the tests use them.
inline FractureSpec fracture_spec(double tensile_strength = 1e6, double cohesion = 2e6,
                                  double friction_angle_deg = 30.0, double energy_I = 10.0,
                                  double energy_II = 50.0) {
  FractureSpec f;
  f.tensile_strength = tensile_strength;
  f.cohesion = cohesion;
  f.friction_angle_deg = friction_angle_deg;
  f.energy_I = energy_I;
  f.energy_II = energy_II;
  return f;
}

// The rock of the cohesive law's tests and of the fracture problems: f_t = 5 MPa, c = 10 MPa,
// φ = 30°, G_I = 50 J/m², G_II = 250 J/m².
inline FractureSpec rock_fracture() {
  return fracture_spec(5e6, 10e6, 30.0, 50.0, 250.0);
}

inline BodySpec box_body(const std::string& name, const Vec3& lo, const Vec3& hi, int nx, int ny,
                         int nz, int material = 0) {
  BodySpec b;
  b.name = name;
  b.material = material;
  b.mesh.kind = MeshSpec::Kind::box;
  b.mesh.box.min = lo;
  b.mesh.box.max = hi;
  b.mesh.box.cells[0] = nx;
  b.mesh.box.cells[1] = ny;
  b.mesh.box.cells[2] = nz;
  return b;
}

inline Scene basic_scene(double end_time) {
  Scene s;
  s.name = "verification";
  s.source_path = "verification";
  s.time.end = end_time;
  return s;
}

// Two blocks [0, L]×[0, w]² and [L, 2L]×[0, w]² (ρ 2500, E 30 GPa, ν 0) joined by an interface
// with the cohesive law `f` at x = L.
inline Scene two_block_scene(double L, double w, int cells_x, int cells_yz, const FractureSpec& f,
                             double end_time) {
  Scene scene = basic_scene(end_time);
  scene.materials.push_back(elastic_material(2500, 30e9, 0.0));
  scene.bodies.push_back(box_body("a", Vec3(0, 0, 0), Vec3(L, w, w), cells_x, cells_yz, cells_yz));
  scene.bodies.push_back(
      box_body("b", Vec3(L, 0, 0), Vec3(2 * L, w, w), cells_x, cells_yz, cells_yz));
  InterfaceSpec joint;
  joint.body_a = 0;
  joint.body_b = 1;
  joint.fracture = f;
  scene.interfaces.push_back(joint);
  return scene;
}

// Run options without progress output or files.
inline RunOptions quiet_options() {
  RunOptions options;
  options.quiet = true;
  options.write_output = false;
  return options;
}

// A simulation without output files.
inline std::unique_ptr<Simulation> quiet_simulation(const Scene& scene) {
  return make_simulation(scene, quiet_options());
}

// Prescribed velocity (components in `mask`) on the nodes of a body or of a region.
inline LoadSpec load_on_body(int body, const Vec3& v, unsigned mask = 7) {
  LoadSpec l;
  l.bodies = {body};
  l.velocity = v;
  l.dof_mask = mask;
  return l;
}

inline LoadSpec load_on_region(const Vec3& lo, const Vec3& hi, const Vec3& v, unsigned mask = 7) {
  LoadSpec l;
  l.region = RegionSpec{lo, hi};
  l.velocity = v;
  l.dof_mask = mask;
  return l;
}

// Tilting table: gravity turned about `axis` at `rate` (rad/s) from `start` (s) until it has
// turned `max` (rad).
inline LoadSpec tilt_load(const Vec3& axis, double rate, double max, double start) {
  LoadSpec l;
  l.kind = LoadSpec::Kind::tilt;
  l.tilt.axis = axis;
  l.tilt.rate = rate;
  l.tilt.max = max;
  l.tilt.start = start;
  return l;
}

// Σ −f over the prescribed nodes of one body: the force the loading device applies (N).  Valid
// after step() while the prescribed velocity is constant (reaction = −f).
inline Vec3 reaction_on_body(const Model& model, int body) {
  Vec3 r = Vec3::Zero();
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    if (model.pieces.body_of(model.nodes.piece[n]) == body && model.nodes.constrained[n])
      r -= vec3_at(model.nodes.f.data(), n);
  return r;
}

// New prescribed velocity of a body's nodes.  The integrator applies it in the next step and books
// the kinetic energy change as the reactions' work (that step's reaction holds the impulse).
inline void set_body_velocity(Model& model, int body, const Vec3& v) {
  model.nodes.keep_prescribed_velocities();
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    if (model.pieces.body_of(model.nodes.piece[n]) == body)
      vec3_at(model.nodes.prescribed_velocity.data(), n) = v;
}

inline LocalIndex broken_joints(const Model& model) {
  LocalIndex n = 0;
  for (auto b : model.joints.broken) n += b;
  return n;
}

}  // namespace fdem::builders
