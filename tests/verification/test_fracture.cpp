// Fracture through the whole engine (REFERENCES 9, 10, 12; docs/fracture-model.md): joint
// placement, the joint stage in the step loop, energy, hand-over to contact.
#include <catch2/catch.hpp>
#include <cmath>

#include "contact/contact_stage.hpp"
#include "core/dynamics.hpp"
#include "fracture/joint_stage.hpp"
#include "scene_helpers.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

// The test rock of the law's unit tests: f_t = 5 MPa, c = 10 MPa, φ = 30°, G_I = 50, G_II = 250.
FractureSpec rock_fracture() {
  FractureSpec f;
  f.tensile_strength = 5e6;
  f.cohesion = 10e6;
  f.friction_angle_deg = 30;
  f.energy_I = 50;
  f.energy_II = 250;
  return f;
}

LoadSpec load_on_body(int body, const Vec3& v, unsigned mask = 7) {
  LoadSpec l;
  l.bodies = {body};
  l.velocity = v;
  l.dof_mask = mask;
  return l;
}

LoadSpec load_on_region(const Vec3& lo, const Vec3& hi, const Vec3& v, unsigned mask = 7) {
  LoadSpec l;
  l.region = RegionSpec{lo, hi};
  l.velocity = v;
  l.dof_mask = mask;
  return l;
}

// Σ −f over the prescribed nodes of one body: the force the loading device applies (N).  Valid
// after step() while the prescribed velocity is constant (reaction = −f).
Vec3 reaction_on_body(const Model& model, int body) {
  Vec3 r = Vec3::Zero();
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    if (model.pieces[model.nodes.piece[n]].body == body && model.nodes.constrained[n])
      r -= vec3_at(model.nodes.f.data(), n);
  return r;
}

void set_body_velocity(Model& model, int body, const Vec3& v) {
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    if (model.pieces[model.nodes.piece[n]].body == body) {
      vec3_at(model.nodes.prescribed_velocity.data(), n) = v;
      vec3_at(model.nodes.v.data(), n) = v;
    }
}

LocalIndex broken_joints(const Model& model) {
  LocalIndex n = 0;
  for (auto b : model.joints.broken) n += b;
  return n;
}

// Two blocks [0, L]×[0, w]² and [L, 2L]×[0, w]² joined by an interface at x = L.
Scene two_block_scene(double L, double w, int cells_x, int cells_yz, const FractureSpec& f,
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

}  // namespace

TEST_CASE("interface placement: coincident faces only, canonical joints, clear error",
          "[verification][fracture]") {
  Scene scene = two_block_scene(0.1, 0.05, 2, 2, rock_fracture(), 1e-3);
  auto sim = quiet_simulation(scene);
  const Model& model = sim->model();
  // 2×2 cells on the interface, 2 triangles each.
  REQUIRE(model.joints.size() == 8);
  double area = 0;
  for (LocalIndex j = 0; j < model.joints.size(); ++j) {
    area += model.joints.area0[j];
    if (j > 0)
      CHECK(model.tets.gid[model.joints.tets[2 * j]] >=
            model.tets.gid[model.joints.tets[2 * j - 2]]);
    const LocalIndex* id = model.joints.nodes.data() + 6 * j;
    for (int i = 0; i < 3; ++i)
      CHECK((vec3_at(model.nodes.x0.data(), id[i]) - vec3_at(model.nodes.x0.data(), id[3 + i]))
                .norm() == 0.0);
    // (a1 − a0) × (a2 − a0) points from A into B
    const Vec3 a0 = vec3_at(model.nodes.x0.data(), id[0]);
    const Vec3 n = (vec3_at(model.nodes.x0.data(), id[1]) - a0)
                       .cross(vec3_at(model.nodes.x0.data(), id[2]) - a0);
    const LocalIndex tet_b = model.joints.tets[2 * j + 1];
    Vec3 cb = Vec3::Zero();
    for (int c = 0; c < 4; ++c)
      cb += 0.25 * vec3_at(model.nodes.x0.data(), model.tets.nodes[4 * tet_b + c]);
    CHECK(n.dot(cb - a0) > 0);
  }
  CHECK(area == Approx(0.05 * 0.05).epsilon(1e-12));
  CHECK(sim->plan().joints);
  CHECK(count_fragments(model) == 1);

  // Blocks a gap apart: no coincident face, a clear error.
  Scene apart = two_block_scene(0.1, 0.05, 2, 2, rock_fracture(), 1e-3);
  apart.bodies[1].mesh.box.min.x() += 1e-3;
  apart.bodies[1].mesh.box.max.x() += 1e-3;
  CHECK_THROWS_WITH(quiet_simulation(apart),
                    Catch::Contains("interfaces[0]") && Catch::Contains("conforming"));
}

TEST_CASE("joints: all splits nodes per tet and bonds every interior face",
          "[verification][fracture]") {
  Scene scene = basic_scene(1e-3);
  scene.materials.push_back(elastic_material(2500, 30e9, 0.2));
  scene.materials[0].fracture = rock_fracture();
  scene.bodies.push_back(box_body("block", Vec3(0, 0, 0), Vec3(0.1, 0.1, 0.1), 2, 2, 2));
  scene.bodies[0].joints = JointPlacement::all;
  auto sim = quiet_simulation(scene);
  const Model& model = sim->model();
  const LocalIndex n_tets = 48;
  REQUIRE(model.tets.size() == n_tets);
  CHECK(model.nodes.size() == 4 * n_tets);
  // Interior faces: (4·48 − boundary 6·4·2) / 2 = 72.
  CHECK(model.joints.size() == 72);
  CHECK(model.pieces.size() == 1);
  for (LocalIndex t = 0; t < n_tets; ++t) CHECK(model.tets.piece[t] == 0);
  CHECK(count_fragments(model) == 1);
  double mass = 0;
  for (double m : model.nodes.mass) mass += m;
  CHECK(mass == Approx(2500 * 1e-3).epsilon(1e-12));
  CHECK(sim->plan().contact);  // tets meet once joints break
}

TEST_CASE("two-block bar pulled apart: peak stress f_t, dissipation G_I (REFERENCES 10)",
          "[verification][fracture]") {
  // Quasi-static pull of the interface through the elastic blocks, ν = 0.
  const double L = 0.1, w = 0.05, v = 0.01;
  const FractureSpec f = rock_fracture();
  Scene scene = two_block_scene(L, w, 2, 1, f, 10e-3);
  scene.loads.push_back(load_on_region(Vec3(-1, -1, -1), Vec3(1e-9, 1, 1), Vec3(-v / 2, 0, 0)));
  scene.loads.push_back(
      load_on_region(Vec3(2 * L - 1e-9, -1, -1), Vec3(1, 1, 1), Vec3(v / 2, 0, 0)));
  auto sim = quiet_simulation(scene);
  Model& model = sim->model();
  double peak = 0, worst_balance = 0;
  while (sim->time() < scene.time.end) {
    sim->step();
    peak = std::max(peak, reaction_on_body(model, 1).x() / (w * w));
    worst_balance = std::max(worst_balance, sim->energy().balance_error());
  }
  const EnergyTerms& e = sim->energy().current();
  const double dissipated = e.dissipated_fracture / (w * w);
  INFO("peak " << peak << " Pa, dissipated " << dissipated << " J/m^2, broken "
               << broken_joints(model) << "/" << model.joints.size() << ", balance "
               << worst_balance << ", steps " << sim->steps_done());
  CHECK(broken_joints(model) == model.joints.size());
  CHECK(std::abs(peak / f.tensile_strength - 1) < 0.02);
  CHECK(std::abs(dissipated / f.energy_I - 1) < 0.005);
  CHECK(e.dissipated_friction == Approx(0).margin(1e-12));
  CHECK(worst_balance < 0.01);
  CHECK(count_fragments(model) == 2);
  for (LocalIndex j = 0; j < model.joints.size(); ++j) {
    CHECK(model.joints.mode[j] == static_cast<std::uint8_t>(FailureMode::tension));
    CHECK(model.joints.failure_time[j] > 0);
  }
}
