// Corner contact (contact.formulation: corners; contact/corner_contact.hpp): impacts keep their
// energy as potential contact's do, and a rocking block's uplift threshold is the rigid block's
// at the default penalty (docs/verification.md, "Corner contact"); the pairs the stage keeps apart
// have no contact.
#include <catch2/catch.hpp>
#include <cmath>

#include "contact/contact_stage.hpp"
#include "contact/corner_contact.hpp"
#include "core/dynamics.hpp"
#include "core/piece_moments.hpp"
#include "impact_scenes.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

// How far a node moved in a hold (m), and in the hold's last fifth; the run's balance error.
struct Tilt {
  double total = 0.0, last_fifth = 0.0, balance = 0.0;
};

// Runs `scene` to its end and watches the node that starts at `corner`.
Tilt watch_hold(const Scene& scene, const Vec3& corner) {
  auto sim = quiet_simulation(scene);
  const Model& model = sim->model();
  LocalIndex node = -1;
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    if ((model.nodes.x0(n) - corner).norm() < 1e-9) node = n;
  REQUIRE(node >= 0);
  const auto moved = [&] {
    return (vec3_at(model.nodes.x.data(), node) - model.nodes.x0(node)).norm();
  };
  const double end = scene.time.end;
  double at_four_fifths = -1.0;
  while (sim->time() < end - 1e-12) {
    sim->step();
    if (at_four_fifths < 0.0 && sim->time() >= 0.8 * end) at_four_fifths = moved();
  }
  Tilt t;
  t.total = moved();
  t.last_fifth = t.total - at_four_fifths;
  t.balance = sim->energy().balance_error();
  return t;
}

// A block b × b × h (1 × 1 × 4 cells, E = `young`, μ 0.8) on a fixed 1 × 1 m base, under gravity
// tilted to `ratio` × its uplift threshold g·b/h, for `end` s.
constexpr double b = 0.1, h = 0.4;  // m
Scene tall_block_scene(double ratio, double young, double end) {
  const double g = 9.81;
  Scene scene = basic_scene(end);
  scene.gravity = Vec3(ratio * g * b / h, 0, -g);
  scene.materials.push_back(elastic_material(2000, young, 0.2));
  scene.materials[0].contact.friction = 0.8;
  scene.bodies.push_back(box_body("base", Vec3(-0.5, -0.5, -0.1), Vec3(0.5, 0.5, 0), 4, 4, 1));
  scene.bodies[0].fixed = true;
  scene.bodies.push_back(
      box_body("block", Vec3(-0.5 * b, -0.5 * b, 0), Vec3(0.5 * b, 0.5 * b, h), 1, 1, 4));
  return scene;
}

// The top corner (heel side) of the tall block (E = 1 GPa, penalty auto) held for 0.3 s under
// local damping 0.8 at a horizontal acceleration `ratio` × g·b/h.
Tilt rocking_hold(double ratio, bool corners) {
  Scene scene = tall_block_scene(ratio, 1e9, 0.3);
  scene.contact_formulation = corners ? ContactFormulation::corners : ContactFormulation::potential;
  scene.quasi_static.local_damping = 0.8;
  scene.time.safety = 0.7;
  return watch_hold(scene, Vec3(-0.5 * b, -0.5 * b, h));
}

}  // namespace

TEST_CASE("corner contact: elastic block–block collision keeps its energy within 0.1 %",
          "[verification][contact][corner_contact]") {
  // The two offset cubes of test_impact_energy.cpp: faces, edges and corners come into contact.
  Scene scene = colliding_cubes();
  scene.contact_formulation = ContactFormulation::corners;
  const ImpactRun r = run_impact(scene);
  INFO("worst balance error " << r.worst_balance << ", peak contact energy " << r.peak_contact
                              << " J of " << r.kinetic_start << " J, kinetic at the end "
                              << r.end.kinetic << " J, momentum drift " << r.momentum_drift);
  CHECK(r.peak_contact > 0.1 * r.kinetic_start);
  CHECK(r.end.contact == 0.0);
  CHECK(r.worst_balance < 1e-3);
  CHECK(r.momentum_drift < 1e-12);
}

TEST_CASE("corner contact: with friction and contact damping the balance closes within 0.1 %",
          "[verification][contact][corner_contact]") {
  // The spinning cube thrown onto a fixed base of test_impact_energy.cpp.
  Scene scene = thrown_cube();
  scene.contact_formulation = ContactFormulation::corners;
  const ImpactRun r = run_impact(scene);
  INFO("worst balance error " << r.worst_balance << "; of " << r.kinetic_start
                              << " J: friction dissipated " << r.end.dissipated_friction
                              << " J, dashpots " << r.end.dissipated_damping << " J");
  CHECK(r.end.dissipated_friction > 0.2 * r.kinetic_start);
  CHECK(r.end.dissipated_damping > 0.02 * r.kinetic_start);
  CHECK(r.worst_balance < 1e-3);
}

TEST_CASE(
    "corner contact: a block of b/h = 0.25 stands still at 0.98 of the rigid uplift acceleration "
    "and turns at 1.02, at the default penalty (docs/references.md 13)",
    "[verification][masonry][corner_contact]") {
  const Tilt below = rocking_hold(0.98, true);
  const Tilt above = rocking_hold(1.02, true);
  const Tilt potential = rocking_hold(0.98, false);
  INFO("corners: tilt at 0.98 " << below.total << " m (last fifth " << below.last_fifth
                                << "), at 1.02 " << above.total << " m (last fifth "
                                << above.last_fifth << "); potential contact at 0.98 "
                                << potential.total << " m");
  // Standing: the elastic lean of block and toe only (~7 µm), and still.
  CHECK(std::abs(below.total) < 2e-5);
  CHECK(std::abs(below.last_fifth) < 1e-7);
  // Turning: away from the load, faster in the last fifth than on average.
  CHECK(above.total > 2e-4);
  CHECK(above.last_fifth > 0.2 * above.total);
  // Potential contact's toe is the softer: its block leans ~20 times as far.
  CHECK(potential.total > 5 * below.total);
  CHECK(below.balance < 1e-3);
  CHECK(above.balance < 1e-3);
}

namespace {

// The tilting-table wall of benchmarks/masonry_thresholds (5 courses of 4 units 0.2 × 0.1 × 0.1 m,
// running bond, lowest course held, μ 0.8, E = 1 GPa, penalty auto) under gravity tilted by
// `ratio` × θc in its plane, tan θc = 0.6 (the rocking wedge's closed form, docs/references.md
// 17), held `hold` s under local damping 0.8: how far its top corner moved, and in the last fifth.
Tilt wall_hold(double ratio, double hold) {
  const double theta = ratio * std::atan(0.6), g = 9.81;
  Scene scene = basic_scene(hold);
  scene.contact_formulation = ContactFormulation::corners;
  scene.gravity = Vec3(-g * std::sin(theta), 0, -g * std::cos(theta));
  scene.quasi_static.local_damping = 0.8;
  scene.time.safety = 0.7;
  scene.materials.push_back(elastic_material(2000, 1e9, 0.2));
  scene.materials[0].contact.friction = 0.8;
  scene.bodies.push_back(running_bond_wall(Vec3(0.2, 0.1, 0.1), 5, 4));
  scene.loads.push_back(load_on_region(Vec3(-1, -1, -0.001), Vec3(2, 1, 0.001), Vec3::Zero()));
  return watch_hold(scene, Vec3(0, 0, 0.5));  // the top course's corner at x = 0
}

}  // namespace

TEST_CASE(
    "corner contact: a dry running-bond wall on a tilting table stands at 0.98 of its closed-form "
    "collapse angle and turns at 1.02, at the default penalty (docs/references.md 17)",
    "[verification][masonry][corner_contact]") {
  // benchmarks/masonry_thresholds/run.py's holds (docs/verification.md, "Corner contact"): 0.98
  // moved 35 µm, +0.11 µm in the last fifth; 1.02 moved 0.11 mm, +36 µm.
  const Tilt below = wall_hold(0.98, 0.2);
  const Tilt above = wall_hold(1.02, 0.12);
  INFO("at 0.98 moved " << below.total << " m (last fifth " << below.last_fifth << "); at 1.02 "
                        << above.total << " m (last fifth " << above.last_fifth << ")");
  CHECK(below.last_fifth < 2e-6);
  CHECK(above.last_fifth > 2e-5);
  CHECK(above.total > 2 * below.total);
}

TEST_CASE("corner contact: the pairs the stage keeps apart are the pairs without contact",
          "[verification][corner_contact]") {
  // A tall block toppling about its toe on a base under corner contact (gravity tilted to twice
  // its uplift threshold): as it turns, pairs of its faces and the base's go from facing each
  // other to not and back.  At every step each candidate pair's contact, evaluated afresh at the
  // step's positions, must be what the stage found: a pair kept apart (corner_pair_apart_travel)
  // had none.
  Scene scene = tall_block_scene(2.0, 1e8, 0.6);
  scene.contact_formulation = ContactFormulation::corners;
  auto sim = quiet_simulation(scene);
  const Model& model = sim->model();
  const auto geometry = [&](const std::vector<double>& x, LocalIndex t) {
    TetCorners corners;
    for (int c = 0; c < 4; ++c) corners.x[c] = vec3_at(x.data(), model.tets.nodes[4 * t + c]);
    TetGeometry g;
    compute_tet_geometry(corners, g);
    return g;
  };
  long evaluated = 0, in_contact = 0, mismatches = 0, steps = 0;
  while (sim->time() < scene.time.end - 1e-12) {
    ++steps;
    const std::vector<double> x = model.nodes.x;  // the step's forces are taken here
    sim->step();
    const ContactStage& stage = *sim->contact_stage();
    for (std::size_t i = 0; i < stage.candidates().size(); ++i) {
      const CandidatePair& pair = stage.candidates()[i];
      const bool contact = corner_contact(geometry(x, pair.a), corner_tet(model, pair.a),
                                          geometry(x, pair.b), corner_tet(model, pair.b), 1e9)
                               .overlapping;
      mismatches += contact != (stage.overlapping()[i] != 0);
      in_contact += contact;
      ++evaluated;
    }
  }
  const auto kept_apart = sim->contact_stage()->pair_steps_kept_apart();
  INFO(steps << " steps, " << evaluated << " pair-steps, " << in_contact << " in contact, "
             << kept_apart << " kept apart by the stage");
  CHECK(mismatches == 0);
  CHECK(in_contact > steps);  // the block stays on its toe
  // It has turned: its top moved along x by more than its width (about 15°).
  double top_shift = 0.0;  // m
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    if (model.nodes.x0(n).z() > h - 1e-9)
      top_shift = std::max(top_shift, vec3_at(model.nodes.x.data(), n).x() - model.nodes.x0(n).x());
  INFO("top moved " << top_shift << " m");
  CHECK(top_shift > b);
  CHECK(kept_apart > static_cast<std::uint64_t>(evaluated / 4));
}
