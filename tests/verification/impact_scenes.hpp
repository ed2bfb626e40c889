// Impacts shared by the energy tests of potential and corner contact (test_impact_energy.cpp,
// test_corner_contact.cpp): two scenes and what a run through them measures.
#pragma once

#include <algorithm>

#include "core/dynamics.hpp"
#include "scene_helpers.hpp"

namespace fdem::testing {

struct ImpactRun {
  double worst_balance = 0.0;   // largest balance error over the run
  double peak_contact = 0.0;    // J
  double kinetic_start = 0.0;   // J, after the first step
  double momentum_drift = 0.0;  // |p − p0| / Σ m|v| at the start
  EnergyTerms end;
};

inline ImpactRun run_impact(const Scene& scene) {
  ImpactRun out;
  auto sim = quiet_simulation(scene);
  sim->step();
  out.kinetic_start = sim->energy().current().kinetic;
  const NodeArrays& nodes = sim->model().nodes;
  const Vec3 p0 = linear_momentum(nodes);
  double scale = 0.0;  // kg m/s: the bodies' momenta may cancel
  for (LocalIndex n = 0; n < nodes.n_owned; ++n)
    scale += nodes.mass[n] * vec3_at(nodes.v.data(), n).norm();
  while (sim->time() < scene.time.end) {
    sim->step();
    out.worst_balance = std::max(out.worst_balance, sim->energy().balance_error());
    out.peak_contact = std::max(out.peak_contact, sim->energy().current().contact);
    out.momentum_drift = std::max(out.momentum_drift, (linear_momentum(nodes) - p0).norm() / scale);
  }
  out.end = sim->energy().current();
  return out;
}

// Two 0.2 m cubes (2 cells a side, E = 0.1 GPa, penalty auto) meeting at ±2 m/s, offset by a
// quarter of their side in y and z: faces, edges and corners come into contact and leave it.
inline Scene colliding_cubes() {
  Scene scene = basic_scene(0.01);
  scene.materials.push_back(elastic_material(2500, 1e8, 0.2));
  scene.time.safety = 0.2;
  scene.bodies.push_back(
      box_body("left", Vec3(-0.201, -0.1, -0.1), Vec3(-0.001, 0.1, 0.1), 2, 2, 2));
  scene.bodies.push_back(
      box_body("right", Vec3(0.001, -0.05, -0.12), Vec3(0.201, 0.15, 0.08), 2, 2, 2));
  scene.bodies[0].velocity = Vec3(2, 0, 0);
  scene.bodies[1].velocity = Vec3(-2, 0, 0);
  return scene;
}

// A spinning 0.2 m cube thrown onto a fixed base (3 m/s along, 2 m/s down, 5 rad/s), friction
// 0.3, contact damping 0.2, under gravity: it bounces, slides and tumbles.
inline Scene thrown_cube() {
  Scene scene = basic_scene(0.03);
  scene.gravity = Vec3(0, 0, -9.81);
  scene.materials.push_back(elastic_material(2500, 1e8, 0.2));
  scene.materials[0].contact.friction = 0.3;
  scene.materials[0].contact.damping = 0.2;
  scene.time.safety = 0.5;
  add_cube_above_base(scene, 0.002);
  scene.bodies[1].velocity = Vec3(3, 0, -2);
  scene.bodies[1].angular_velocity = Vec3(0, 5, 0);
  return scene;
}

}  // namespace fdem::testing
