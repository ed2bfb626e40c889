// Energy of impacts (docs/verification.md, "Impact energy"): an elastic collision keeps its energy
// to the integration error and its momentum exactly; with friction and contact dashpots the
// ledger's dissipation (the work of those forces by the integrator's trapezoid rule) closes the
// balance to the same error.
#include <catch2/catch.hpp>
#include <cmath>

#include "core/dynamics.hpp"
#include "impact_scenes.hpp"

using namespace fdem;
using namespace fdem::testing;

TEST_CASE("elastic block–block collision: energy within 0.1 %, momentum exact",
          "[verification][contact][impact]") {
  // Two 0.2 m cubes (2 cells a side, E = 0.1 GPa, penalty auto) meet at ±2 m/s, offset by a
  // quarter of their side in y and z: faces, edges and corners come into contact and leave it.
  // The balance error is the integration error of the contact's onset and release, O((ω_c Δt)²):
  // measured worst 0.39 / 0.27 / 0.10 / 0.066 / 0.015 / 0.003 % at time.safety 0.5 / 0.4 / 0.25 /
  // 0.2 / 0.1 / 0.05 (the same with the ledger before and after the trapezoid contact work: no
  // friction, no dashpot).
  const ImpactRun r = run_impact(colliding_cubes());
  INFO("worst balance error " << r.worst_balance << ", peak contact energy " << r.peak_contact
                              << " J of " << r.kinetic_start << " J, kinetic at the end "
                              << r.end.kinetic << " J, momentum drift " << r.momentum_drift);
  CHECK(r.peak_contact > 0.1 * r.kinetic_start);  // they really collided
  CHECK(r.end.contact == 0.0);                    // and came apart
  CHECK(r.worst_balance < 1e-3);
  CHECK(r.momentum_drift < 1e-12);
}

TEST_CASE("friction and contact damping: the energy balance closes within 0.1 %",
          "[verification][contact][impact]") {
  // A spinning 0.2 m cube thrown onto a fixed base (3 m/s along, 2 m/s down, 5 rad/s), friction
  // 0.3, contact damping 0.2, under gravity: it bounces, slides and tumbles.  Friction and dashpot
  // dissipation are the work of those forces with the trapezoid rule of the integrator.
  // Measured worst balance error: 0.21 % when they were counted from the velocities before the
  // step alone (slip work of the return map, dashpot −F·v_n−½·Δt), 0.026 % with the trapezoid.
  const ImpactRun r = run_impact(thrown_cube());
  INFO("worst balance error " << r.worst_balance << "; of " << r.kinetic_start
                              << " J: friction dissipated " << r.end.dissipated_friction
                              << " J, dashpots " << r.end.dissipated_damping << " J");
  CHECK(r.end.dissipated_friction > 0.2 * r.kinetic_start);  // both mechanisms did work
  CHECK(r.end.dissipated_damping > 0.02 * r.kinetic_start);
  CHECK(r.worst_balance < 1e-3);
}

TEST_CASE("a settled block on a 30° incline with μ = 0.7 holds without any damping",
          "[verification][contact][friction]") {
  // The incline of issue 15 (0.4 × 0.4 × 0.3 m block, 4 × 4 × 3 cells, τ/μσ = 0.82), with E =
  // 0.2 GPa for a longer step.  Started at rest on the base under full gravity, the undamped block
  // keeps ringing on its contact springs (normal force 0.2–2.5 × its weight) and slips whenever
  // the normal force is low (docs/verification.md, "Static friction on an incline").  Settled
  // first under element damping and then run without any, the stick state holds it.
  const double g = 9.81, slope = 30 * M_PI / 180;
  Scene scene = basic_scene(0.3);
  scene.gravity = g * Vec3(std::sin(slope), 0, -std::cos(slope));
  scene.materials.push_back(elastic_material(2400, 2e8, 0.2));
  scene.materials[0].contact.friction = 0.7;
  scene.materials[0].damping = 0.3;
  scene.bodies.push_back(box_body("base", Vec3(-0.6, -0.5, -0.2), Vec3(0.6, 0.5, 0), 6, 5, 1));
  scene.bodies[0].fixed = true;
  scene.bodies.push_back(box_body("block", Vec3(-0.2, -0.2, 0), Vec3(0.2, 0.2, 0.3), 4, 4, 3));
  auto sim = quiet_simulation(scene);
  while (sim->time() < 0.1) sim->step();
  std::fill(sim->model().tets.viscosity.begin(), sim->model().tets.viscosity.end(), 0.0);
  const double settled = piece_motions(sim->model())[1].centroid.x();
  const double friction_before = sim->energy().current().dissipated_friction;
  const double kinetic_settled = sim->energy().current().kinetic;
  // The block's position every 10 ms: it vibrates slowly on its stuck contacts (a period of
  // ~0.1 s) and does not drift.
  double farthest = 0.0;
  for (int row = 1; row <= 20; ++row) {
    while (sim->time() < 0.1 + 0.01 * row) sim->step();
    farthest = std::max(farthest, std::abs(piece_motions(sim->model())[1].centroid.x() - settled));
  }
  const double crept = piece_motions(sim->model())[1].centroid.x() - settled;
  const double kinetic = sim->energy().current().kinetic;
  INFO("kinetic after settling " << kinetic_settled << " J; slid " << settled
                                 << " m while settling, then at most " << farthest << " m ("
                                 << crept << " m at the end) in 0.2 s undamped; kinetic " << kinetic
                                 << " J, friction dissipated meanwhile "
                                 << sim->energy().current().dissipated_friction - friction_before
                                 << " J");
  CHECK(farthest < 2e-7);
  CHECK(kinetic < 1e-6);
}

TEST_CASE(
    "a block dropped flat on a soft contact: the dashpot sized by the bodies damps its bounce "
    "at least as a single spring–dashpot of ratio ξ, the one sized by the tets does not",
    "[verification][contact][impact]") {
  // A 0.2 × 0.2 × 0.2 m block (2 cells a side, E = 1 GPa) lands at 0.1 m/s flat on a fixed base
  // through a contact 100 times softer than the block (p = E/100): it bounces on the contact
  // springs as a rigid body, 8 tet pairs carrying its 16 kg.  One spring–dashpot of ratio ξ
  // returns e = exp(−πξ/√(1 − ξ²)) of the speed (0.527 at ξ = 0.2).  Sized by the block's mass
  // each pair damps the bounce by ξ or more (measured e = 0.358); sized by the tets' masses they
  // damp it by about ξ√(8·m_tet/M) (measured e = 0.799).  Without damping e = 0.9995.
  const double xi = 0.2, speed = 0.1;
  const auto rebound = [&](bool body_dashpot) {
    Scene scene = basic_scene(0.01);
    scene.materials.push_back(elastic_material(2000, 1e9, 0.2));
    scene.materials[0].contact.auto_penalty = false;
    scene.materials[0].contact.penalty = 1e7;
    scene.materials[0].contact.friction = 0.0;
    scene.materials[0].contact.damping = xi;
    scene.contact_body_dashpot = body_dashpot;
    scene.bodies.push_back(box_body("base", Vec3(-0.3, -0.3, -0.1), Vec3(0.3, 0.3, 0), 3, 3, 1));
    scene.bodies[0].fixed = true;
    scene.bodies.push_back(box_body("block", Vec3(-0.1, -0.1, 0), Vec3(0.1, 0.1, 0.2), 2, 2, 2));
    scene.bodies[1].velocity = Vec3(0, 0, -speed);
    auto sim = quiet_simulation(scene);
    double worst = 0.0;
    while (sim->time() < scene.time.end) {
      sim->step();
      worst = std::max(worst, sim->energy().balance_error());
    }
    INFO("worst balance error " << worst);
    CHECK(sim->energy().current().contact == 0.0);  // it has left the base
    CHECK(worst < 1e-3);
    return piece_motions(sim->model())[1].velocity.z() / speed;
  };
  const double single = std::exp(-M_PI * xi / std::sqrt(1 - xi * xi));
  const double bodies = rebound(true), tets = rebound(false);
  INFO("restitution: bodies " << bodies << ", tets " << tets << ", one spring-dashpot " << single);
  CHECK(bodies > 0.0);
  CHECK(bodies < single);
  CHECK(tets > 0.7);
}
