// Scene builders for the verification tests (the shared ones of drivers/scene_builders.hpp) and
// what a masonry test measures while a load is held.
#pragma once

#include <chrono>
#include <cmath>

#include "core/dynamics.hpp"
#include "drivers/scene_builders.hpp"

namespace fdem::testing {
using namespace fdem::builders;

// A running-bond wall of `courses` courses of `units` units (running bond: n − 1 full and two
// half units in every other course), exactly touching (no mortar gap), 2 × 1 × 1 cells per unit.
inline BodySpec running_bond_wall(const Vec3& unit, int courses, int units, int material = 0) {
  BodySpec wall;
  wall.name = "wall";
  wall.material = material;
  wall.mesh.kind = MeshSpec::Kind::wall;
  WallMeshSpec& w = wall.mesh.wall;
  w.bond = WallMeshSpec::Bond::running;
  w.unit = unit;
  w.courses = courses;
  w.units_per_course = units;
  return wall;
}

// A block b (x) × 0.2 (y) × h (z) generated as a one-block tower on a fixed base.
// Contact penalty p = 4E.  A penalty contact is a compliant foundation: near the tipping point
// the contact zone shrinks towards the edge and the pivot sits inside it, so the block tips early
// by about (N/(p·d))^(1/3) (N the weight, d the depth); with E = 1e8, p = 4e8 this is ~0.5° of
// tilt.
inline Scene block_on_base(double b, double h, double friction, double end_time,
                           double young = 1e8) {
  Scene scene = basic_scene(end_time);
  scene.materials.push_back(elastic_material(2000, young, 0.2));
  MaterialSpec& m = scene.materials[0];
  m.contact.friction = friction;
  m.contact.damping = 0.5;
  m.contact.auto_penalty = false;
  m.contact.penalty = 4 * young;
  m.damping = 0.5;
  scene.time.safety = 0.5;
  scene.bodies.push_back(box_body("base", Vec3(-0.6, -0.3, -0.1), Vec3(0.6, 0.3, 0), 6, 3, 1));
  scene.bodies[0].fixed = true;
  BodySpec block;
  block.name = "block";
  block.material = 0;
  block.mesh.kind = MeshSpec::Kind::tower;
  block.mesh.tower.block = Vec3(b, 0.2, h);
  block.mesh.tower.blocks = 1;
  block.mesh.tower.cells[0] = 2;
  block.mesh.tower.cells[1] = 2;
  block.mesh.tower.cells[2] = static_cast<int>(std::lround(2 * h / b));
  block.mesh.tower.origin = Vec3(-0.5 * b, -0.1, 0);
  scene.bodies.push_back(block);
  return scene;
}

// Bodies 0 and 1 of material 0: a fixed 1 × 1 × 0.1 m base (5 × 5 × 1 cells, top at z = 0) and a
// 0.2 m cube (2 × 2 × 2 cells) centred over it, its bottom `gap` (m) above the base.
inline void add_cube_above_base(Scene& scene, double gap) {
  scene.bodies.push_back(box_body("base", Vec3(-0.5, -0.5, -0.1), Vec3(0.5, 0.5, 0), 5, 5, 1));
  scene.bodies[0].fixed = true;
  scene.bodies.push_back(
      box_body("block", Vec3(-0.1, -0.1, gap), Vec3(0.1, 0.1, 0.2 + gap), 2, 2, 2));
}

// What a block did while a load was held: slid along x (m) and turned (rad) during the hold.
struct HoldResult {
  double slid = 0;
  double turned = 0;
  double wall = 0;  // s
  double balance = 0;
};

// Steps `sim` to its end; the hold starts at `hold_start`.  `piece` is the block (piece 1 unless
// told).
inline HoldResult run_hold(Simulation& sim, double hold_start, int piece = 1) {
  HoldResult r;
  const auto clock = std::chrono::steady_clock::now();
  Vec3 x0 = Vec3::Zero(), turn0 = Vec3::Zero();
  bool held = false;
  while (sim.time() < sim.scene().time.end - 1e-12) {
    sim.step();
    if (!held && sim.time() >= hold_start) {
      const PieceMotion m = piece_motions(sim.model())[piece];
      x0 = m.centroid;
      turn0 = m.rotation;
      held = true;
    }
  }
  const PieceMotion m = piece_motions(sim.model())[piece];
  r.slid = std::abs(m.centroid.x() - x0.x());
  r.turned = (m.rotation - turn0).norm();
  r.balance = sim.energy().balance_error();
  r.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock).count();
  return r;
}

}  // namespace fdem::testing
