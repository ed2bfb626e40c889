// Masonry closed-form checks on generated scenes: a block on a tilting table slides at tanθ = μ or
// topples at tanθ = b/h (docs/references.md 6 idea), a slender block on a moving base lifts off at
// a = g·b/h (docs/references.md 13, Housner), the dry-joint shear of a generated wall course
// (docs/references.md 12), a dry running-bond wall with exactly touching units standing under
// gravity, and a block slipping on a table under a rectangular acceleration pulse
// (docs/references.md 18, Newmark).
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>

#include "core/dynamics.hpp"
#include "drivers/loads.hpp"
#include "scene_helpers.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

constexpr double deg = M_PI / 180;

// Tilting table (gravity turned about +y, towards −x): the block settles 0.2 s on the table
// tilted `first` degrees below `angle`, which then tilts at 30°/s to 2° below `angle` and at
// 4°/s on to `angle`, held 0.4 s.  (A start far from tipping saves steps; a block that may slide
// starts level: the bounce of the sudden start on a tilted table makes it creep.)
HoldResult tilt_and_hold(double b, double h, double friction, double angle, double first,
                         double young) {
  const double fast = 30.0, slow = 4.0, pre = 2.0, start = 0.2, g = 9.81;
  const double slow_start = start + (first - pre) / fast;
  const double hold_start = slow_start + pre / slow, end = hold_start + 0.4;
  Scene scene = block_on_base(b, h, friction, end, young);
  const double from = angle - first;
  scene.gravity = g * Vec3(-std::sin(from * deg), 0, -std::cos(from * deg));
  for (int k = 0; k < 2; ++k)  // two tilts about one axis add up
    scene.loads.push_back(tilt_load(Vec3(0, 1, 0), (k == 0 ? fast : slow) * deg,
                                    (k == 0 ? first - pre : pre) * deg,
                                    k == 0 ? start : slow_start));
  auto sim = quiet_simulation(scene);
  REQUIRE(std::abs(gravity_at(scene, end).x() + g * std::sin(angle * deg)) < 1e-9);
  return run_hold(*sim, hold_start + 0.1);  // measured over the last 0.3 s
}

}  // namespace

TEST_CASE("tilting table: a block slides at tanθ = μ when μ < b/h, topples at tanθ = b/h otherwise",
          "[verification][masonry][long]") {
  const double b = 0.25, h = 0.5;                // b/h = 0.5
  const double topple = std::atan(b / h) / deg;  // 26.57°
  // Held below and above the closed-form angle (sliding ±0.5°, toppling ±1°): still below,
  // moving above.
  {
    const double mu = 0.4, slide = std::atan(mu) / deg;  // 21.80° < 26.57°: slides first
    const HoldResult below = tilt_and_hold(b, h, mu, slide - 0.5, slide - 0.5, 1e7);
    const HoldResult above = tilt_and_hold(b, h, mu, slide + 0.5, slide + 0.5, 1e7);
    INFO("μ = 0.4, slide angle " << slide << "°: at −0.5° slid " << below.slid << " m, turned "
                                 << below.turned << " rad; at +0.5° slid " << above.slid
                                 << " m, turned " << above.turned << " rad (wall " << below.wall
                                 << " + " << above.wall << " s)");
    CHECK(below.slid < 1e-4);
    CHECK(above.slid > 5e-3);
    CHECK(above.turned < 1e-2);  // slides, does not topple
    CHECK(above.balance < 0.01);
  }
  {
    const double mu = 0.7;  // 35° > 26.57°: topples first
    const HoldResult below = tilt_and_hold(b, h, mu, topple - 1.0, 6, 1e8);
    const HoldResult above = tilt_and_hold(b, h, mu, topple + 1.0, 6, 1e8);
    INFO("μ = 0.7, topple angle " << topple << "°: at −1° turned " << below.turned << " rad, slid "
                                  << below.slid << " m; at +1° turned " << above.turned
                                  << " rad, slid " << above.slid << " m (wall " << below.wall
                                  << " + " << above.wall << " s)");
    CHECK(below.turned < 2e-3);
    CHECK(above.turned > 2e-2);
    CHECK(below.slid < 1e-4);
  }
}

namespace {

// What a block on a base accelerated at a constant level did while the level was held.
struct RockResult {
  double max_turn = 0;     // largest rotation during the hold (rad)
  double final_turn = 0;   // rotation at the end of the hold (rad)
  double max_heel = 0;     // largest rise of the heel's bottom corner nodes during the hold (m)
  double penetration = 0;  // static penetration of the block into the base before the load (m)
  double wall = 0;         // s
  long steps = 0;
  double balance = 0;
};

// Rocking block b × d × h = 0.25 × 0.25 × 0.5 m (b/h = 0.5, a_c = g/2) on a fixed base under a
// horizontal acceleration `level`·a_c (in the base's frame: gravity plus level·a_c along −x, so
// the block tips about its −x bottom edge, the toe; the +x one is the heel).
//
// The settings make the penalty contact nearly a rigid foundation, at the least cost (see
// docs/verification.md, "Masonry"): a penalty contact is a Winkler foundation of stiffness
// k ≈ 30 p per metre here; tipped by θ about the toe, the block rests on a strip of width
// w = √(2N/(k·d·θ)) and its restoring arm is b/2 − hθ/2 − w/3, whose largest value lowers the
// uplift acceleration by ε ≈ 2·(2ρg(h/b)²/(9k))^(1/3) of a_c.  ε falls with a stiffer penalty and
// a stockier block: 3 % with the former b/h = 1/4, p = 4e8 Pa, 0.7 % at p = 4E = 1.6e10 Pa, less
// here at the default penalty (10 E = 4e10 Pa), with coarse tets (one cell across) so that the
// contact-limited step stays long.  Near the threshold
// the rocking mode is slow (period ~0.4 s), so the load comes quickly to 0.9 of its level and
// then slowly (0.2 s) to the level, held 0.3 s; a little contact damping (0.1) keeps the step long.
RockResult rock_at(double level) {
  const double b = 0.25, d = 0.25, h = 0.5, g = 9.81, a_c = g * b / h;
  const double settle = 0.05, fast = 0.1, slow = 0.2, hold = 0.3;
  const double young = 4e9;
  Scene scene = basic_scene(settle + fast + slow + hold);
  scene.materials.push_back(elastic_material(2000, young, 0.2));
  MaterialSpec& m = scene.materials[0];
  m.contact.friction = 0.8;  // > b/h: the block cannot slide before it tips
  m.contact.damping = 0.1;
  m.damping = 0.5;  // the contact penalty is the default (auto: 10 E)
  scene.time.safety = 0.8;
  scene.gravity = Vec3(0, 0, -g);
  scene.bodies.push_back(
      box_body("base", Vec3(-0.375, -0.25, -0.25), Vec3(0.375, 0.25, 0), 3, 2, 1));
  scene.bodies[0].fixed = true;
  BodySpec block;
  block.name = "block";
  block.material = 0;
  block.mesh.kind = MeshSpec::Kind::tower;
  block.mesh.tower.block = Vec3(b, d, h);
  block.mesh.tower.blocks = 1;
  block.mesh.tower.cells[0] = 1;
  block.mesh.tower.cells[1] = 1;
  block.mesh.tower.cells[2] = 2;
  block.mesh.tower.origin = Vec3(-0.5 * b, -0.5 * d, 0);
  scene.bodies.push_back(block);
  for (int k = 0; k < 2; ++k) {  // two ramps add up: 0.9 of the level in `fast`, the rest in `slow`
    LoadSpec ramp;
    ramp.kind = LoadSpec::Kind::ramp;
    ramp.ramp.direction = Vec3(-1, 0, 0);
    ramp.ramp.max = (k == 0 ? 0.9 : 0.1) * level * a_c;
    ramp.ramp.rate = ramp.ramp.max / (k == 0 ? fast : slow);
    ramp.ramp.start = k == 0 ? settle : settle + fast;
    scene.loads.push_back(ramp);
  }
  const double hold_start = settle + fast + slow;
  REQUIRE(std::abs(gravity_at(scene, hold_start).x() + level * a_c) < 1e-9);
  auto sim = quiet_simulation(scene);
  const Model& model = sim->model();
  // The heel's bottom corner nodes (x = +b/2, z = 0 at t = 0) and their lowest point at rest.
  std::vector<LocalIndex> heel, bottom;
  for (LocalIndex n = 0; n < model.nodes.size(); ++n) {
    const Vec3 X = model.nodes.x0(n);
    if (model.nodes.piece[n] != 1 || std::abs(X.z()) > 1e-9) continue;
    bottom.push_back(n);
    if (X.x() > 0.5 * b - 1e-9) heel.push_back(n);
  }
  REQUIRE(heel.size() == 2);
  RockResult r;
  const auto clock = std::chrono::steady_clock::now();
  Vec3 turn0 = Vec3::Zero();
  bool held = false;
  while (sim->time() < scene.time.end - 1e-12) {
    sim->step();
    ++r.steps;
    if (!held && sim->time() >= settle) {
      turn0 = piece_motions(model)[1].rotation;
      for (LocalIndex n : bottom)
        r.penetration = std::max(r.penetration, -model.nodes.x[3 * n + 2]);
    }
    held = sim->time() >= settle;
    if (sim->time() < hold_start) continue;
    const double turn = (piece_motions(model)[1].rotation - turn0).norm();
    r.max_turn = std::max(r.max_turn, turn);
    r.final_turn = turn;
    for (LocalIndex n : heel) r.max_heel = std::max(r.max_heel, model.nodes.x[3 * n + 2]);
  }
  r.balance = sim->energy().balance_error();
  r.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock).count();
  return r;
}

}  // namespace

TEST_CASE(
    "rocking block on a moving base lifts off at a = g·b/h within 2 % (docs/references.md 13, "
    "Housner)",
    "[verification][masonry]") {
  // Lift-off is the loss of rotational equilibrium: the block turns away about its toe.  With a
  // penalty (compliant) contact the heel unloads long before that (at the kern limit, a_c/3 for a
  // Winkler foundation) and at 0.98 a_c rises by ~3600 static penetrations (3.0e-5 m against
  // 8.4e-9 m), so the heel counts as lifted off when it rises by 1 % of b (2.5 mm, θ ≈ 0.01 rad),
  // and as down while it stays within 0.1 % of b (θ < 1e-3 rad).  Measured at the default
  // penalty: at 0.98 a_c the block rocks in place (≤ 1.3e-4 rad), at 1.02 a_c it has turned
  // 0.019 rad after 0.3 s of hold and is accelerating (at p = 4E: 3.5e-4 and 0.022 rad, and the
  // threshold between 0.985 a_c, which stays, and 0.99 a_c, which lifts off).
  const double b = 0.25;
  const RockResult below = rock_at(0.98);
  const RockResult above = rock_at(1.02);
  INFO("static penetration " << below.penetration << " m; held at 0.98 a_c: largest turn "
                             << below.max_turn << " rad, heel up " << below.max_heel
                             << " m; at 1.02 a_c: turn " << above.final_turn << " rad, heel up "
                             << above.max_heel << " m (" << below.steps << " + " << above.steps
                             << " steps, wall " << below.wall << " + " << above.wall << " s)");
  CHECK(below.max_turn < 1e-3);
  CHECK(below.max_heel < 1e-3 * b);
  CHECK(above.final_turn > 1e-2);
  CHECK(above.max_heel > 1e-2 * b);
  CHECK(above.final_turn > above.max_turn - 1e-12);  // still turning away at the end of the hold
  CHECK(below.balance < 0.01);
  CHECK(above.balance < 0.01);
}

namespace {

// Nodes of one piece: prescribed velocity v (all components).
void drive_piece(Model& model, std::int32_t piece, const Vec3& v) {
  model.nodes.keep_prescribed_velocities();
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    if (model.nodes.piece[n] == piece) {
      model.nodes.constrained[n] = 7;
      vec3_at(model.nodes.prescribed_velocity.data(), n) = v;
    }
}

// Σ −f over the nodes of a driven piece: the force the loading device applies (N).
Vec3 reaction_on_piece(const Model& model, std::int32_t piece) {
  Vec3 r = Vec3::Zero();
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    if (model.nodes.piece[n] == piece) r -= vec3_at(model.nodes.f.data(), n);
  return r;
}

}  // namespace

TEST_CASE(
    "dry-joint shear on a generated wall course: τ_peak = μσ_n, no softening (docs/references.md "
    "12)",
    "[verification][masonry]") {
  // One course of two 100 × 200 × 200 mm units (stack bond): the head joint between them is the
  // 200 × 200 mm dry joint, contact with Coulomb friction μ = 0.65 and no cohesion.  The left unit
  // is held, the right one pressed onto it by σ_n and then slid along y by 0.5 mm at 0.5 m/s.
  const double mu = 0.65, area = 0.2 * 0.2;
  for (double sigma : {0.25e6, 0.5e6, 1.0e6}) {
    Scene scene = basic_scene(1.0);
    scene.materials.push_back(elastic_material(2500, 30e9, 0.0));
    scene.materials[0].contact.friction = mu;
    scene.contact_buffer = 2e-4;
    BodySpec wall;
    wall.name = "course";
    wall.material = 0;
    wall.mesh.kind = MeshSpec::Kind::wall;
    wall.mesh.wall.unit = Vec3(0.1, 0.2, 0.2);
    wall.mesh.wall.units_per_course = 2;
    wall.mesh.wall.cells[0] = 1;
    wall.mesh.wall.cells[1] = 2;
    wall.mesh.wall.cells[2] = 2;
    scene.bodies.push_back(wall);
    auto sim = quiet_simulation(scene);
    Model& model = sim->model();
    REQUIRE(model.pieces.size() == 2);
    const std::int32_t held = model.pieces[0].centroid0.x() < 0.1 ? 0 : 1, moved = 1 - held;
    drive_piece(model, held, Vec3::Zero());
    drive_piece(model, moved, Vec3::Zero());
    const double dt = sim->time_step();
    // Press: half the estimated overlap, measure, then the rest (contact force ∝ overlap here).
    const double penalty = 10 * 30e9, estimate = 0.5 * sigma * 0.1 / (8 * penalty);
    const int press_steps = 100;
    drive_piece(model, moved, Vec3(-estimate / (press_steps * dt), 0, 0));
    for (int s = 0; s < press_steps; ++s) sim->step();
    drive_piece(model, moved, Vec3::Zero());
    sim->step();
    const double measured = -reaction_on_piece(model, moved).x() / area;
    REQUIRE(measured > 0);
    drive_piece(model, moved, Vec3(-estimate * (sigma / measured - 1) / (press_steps * dt), 0, 0));
    for (int s = 0; s < press_steps; ++s) sim->step();
    drive_piece(model, moved, Vec3(0, 0.5, 0));
    const long slide_steps = std::lround(0.5e-3 / (0.5 * dt));
    double peak = 0, sigma_at_peak = 0, sigma_start = 0, final_tau = 0, final_sigma = 0;
    for (long s = 0; s < slide_steps; ++s) {
      sim->step();
      if (s == 0) continue;  // the velocity change's impulse
      const Vec3 r = reaction_on_piece(model, moved);
      const double tau = r.y() / area, sig = -r.x() / area;
      if (s == 1) sigma_start = sig;
      if (tau > peak) {
        peak = tau;
        sigma_at_peak = sig;
      }
      final_tau = tau;
      final_sigma = sig;
    }
    INFO("σ_n = " << sigma_start << " Pa (target " << sigma << "): τ_peak " << peak
                  << " Pa = " << peak / sigma_at_peak << " σ_n, end " << final_tau / final_sigma
                  << " σ_n, peak force " << peak * area << " N");
    CHECK(std::abs(sigma_start / sigma - 1) < 0.02);
    CHECK(std::abs(peak / (mu * sigma_at_peak) - 1) < 0.02);
    CHECK(std::abs(final_tau / (mu * final_sigma) - 1) < 0.02);  // no softening
    if (sigma == 0.5e6) CHECK(std::abs(peak * area * (0.5e6 / sigma_at_peak) / 13e3 - 1) < 0.02);
    CHECK(sim->energy().balance_error() < 0.01);
  }
}

TEST_CASE("dry running-bond wall with exactly touching units (mortar gap 0) stands under gravity",
          "[verification][masonry]") {
  // The dry-stone wall example with mortar_gap 0: 6 courses of 4 stones (0.3 × 0.15 × 0.1 m) in
  // running bond, contact only (friction 0.6, contact damping 0.3), on a fixed table.  Exactly
  // touching coplanar faces give round-off slivers of overlap between tets of neighbouring stones;
  // such a sliver (4.5e-52 m³, F = 1e-25 N) once had its centroid weights ~3e14 and its dashpot
  // pushed the stones apart (an inverted tet at step 8).  With the centroid weights clamped to
  // [0, 1] and no dashpot on round-off slivers (contact/) the wall settles and stands.
  Scene scene = basic_scene(1.0);
  scene.materials.push_back(elastic_material(2200, 2e8, 0.2));
  MaterialSpec& m = scene.materials[0];
  m.damping = 0.3;
  m.contact.auto_penalty = false;
  m.contact.penalty = 4e8;
  m.contact.friction = 0.6;
  m.contact.damping = 0.3;
  scene.time.safety = 0.5;
  scene.gravity = Vec3(0, 0, -9.81);
  scene.bodies.push_back(box_body("table", Vec3(-0.2, -0.2, -0.1), Vec3(1.4, 0.35, 0), 8, 2, 1));
  scene.bodies[0].fixed = true;
  scene.bodies.push_back(running_bond_wall(Vec3(0.3, 0.15, 0.1), 6, 4));
  auto sim = quiet_simulation(scene);
  const Model& model = sim->model();
  REQUIRE(model.pieces.size() == 28);  // the table, 3 courses of 4 stones, 3 of 3 + 2 halves
  const auto clock = std::chrono::steady_clock::now();
  const int steps = 600;
  double worst_balance = 0;
  for (int s = 0; s < steps; ++s) {
    REQUIRE_NOTHROW(sim->step());
    worst_balance = std::max(worst_balance, sim->energy().balance_error());
  }
  const double wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock).count();
  bool finite = true;
  for (double x : model.nodes.x) finite = finite && std::isfinite(x);
  REQUIRE(finite);
  // Largest displacement and speed of a stone: the stones settle by the contact penetration and
  // their own shortening (9e-6 m measured); a free fall would be 0.5 g t² = 3.7e-4 m by then, at
  // g·t = 0.085 m/s (the stones still bounce at ~5e-3 m/s).
  double moved = 0, speed = 0;
  const std::vector<PieceMotion> motion = piece_motions(model);
  for (std::size_t p = 0; p < motion.size(); ++p) {
    moved = std::max(moved, (motion[p].centroid - model.pieces[p].centroid0).norm());
    speed = std::max(speed, motion[p].velocity.norm());
  }
  const double t = sim->time(), free_fall = 0.5 * 9.81 * t * t;
  INFO(steps << " steps to t = " << t << " s (wall " << wall_seconds
             << " s): largest stone displacement " << moved << " m (free fall " << free_fall
             << " m), speed " << speed << " m/s, worst balance error " << worst_balance);
  CHECK(moved < 0.1 * free_fall);
  CHECK(speed < 0.2 * 9.81 * t);
  CHECK(worst_balance < 0.01);
}

TEST_CASE(
    "Newmark sliding block: a rectangular base pulse slides it A·t0²(A − μg)/(2μg), then it "
    "sticks",
    "[verification][masonry]") {
  // A 0.4 × 0.2 × 0.2 m block (μ = 0.3, too squat to rock: b/h = 2 > A/g) rests 0.1 s on a table
  // that then accelerates at A = 0.5 g for t0 = 0.1 s (1e-4 s rise and fall) and moves on at
  // constant speed.  The block slips while the table accelerates (its own acceleration is μg) and
  // until it has caught up; Newmark's rigid-block slip is A·t0²·(A − μg)/(2μg) = 16.35 mm, after
  // which it rides with the table.
  const double g = 9.81, mu = 0.3, A = 0.5 * g, t0 = 0.1, start = 0.1, rise = 1e-4;
  const double expected = A * t0 * t0 * (A - mu * g) / (2 * mu * g);
  const double slip_ends = start + t0 + (A - mu * g) * t0 / (mu * g), end = slip_ends + 0.15;
  Scene scene = block_on_base(0.4, 0.2, mu, end);
  scene.gravity = Vec3(0, 0, -g);
  scene.bodies[0].fixed = false;  // the table is driven by the base motion
  LoadSpec pulse;
  pulse.kind = LoadSpec::Kind::base_motion;
  pulse.bodies = {0};
  pulse.base_motion.time = {0.0, start, start + rise, start + t0, start + t0 + rise, end + 1.0};
  pulse.base_motion.acceleration = {0.0, 0.0, A, A, 0.0, 0.0};
  pulse.base_motion.direction = Vec3(1, 0, 0);
  scene.loads.push_back(pulse);
  auto sim = quiet_simulation(scene);
  const auto relative_x = [&] {
    const std::vector<PieceMotion> m = piece_motions(sim->model());
    return m[1].centroid.x() - m[0].centroid.x();
  };
  const auto clock = std::chrono::steady_clock::now();
  double at_start = 0.0, at_hold = 0.0;
  long steps = 0;
  bool started = false, holding = false;
  while (sim->time() < end - 1e-12) {
    sim->step();
    ++steps;
    if (!started && sim->time() >= start) {
      at_start = relative_x();
      started = true;
    }
    if (!holding && sim->time() >= end - 0.1) {
      at_hold = relative_x();
      holding = true;
    }
  }
  const double slip = at_start - relative_x(), creep = std::abs(relative_x() - at_hold);
  const std::vector<PieceMotion> m = piece_motions(sim->model());
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock).count();
  INFO("slip " << slip << " m, Newmark " << expected << " m (" << (slip / expected - 1) * 100
               << " %); over the last 0.1 s " << creep << " m; relative velocity "
               << (m[1].velocity - m[0].velocity).norm() << " m/s; " << steps << " steps, " << wall
               << " s");
  CHECK(std::abs(slip / expected - 1) < 0.02);
  CHECK(creep < 1e-4);
  CHECK((m[1].velocity - m[0].velocity).norm() < 1e-3);
  CHECK(sim->energy().balance_error() < 0.01);
}
