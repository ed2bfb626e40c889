// Static friction on an incline with the quasi-static mode's settling (quasi_static.until): a
// block and a column of three blocks at 95 % of their friction capacity stay put for 2 s of
// dynamics with 2 % contact damping, sliding starts between 0.995 and 1.005 tanθ = μ, and the same
// block loaded suddenly without settling creeps (the vibration of the sudden load,
// docs/verification.md).
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "scene_helpers.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

constexpr double deg = M_PI / 180;
constexpr double g = 9.81;

// A 0.4 × 0.4 × 0.3 m block (2 × 2 × 2 cells) on a fixed 0.8 × 0.8 m base (E = 0.1 GPa, friction μ,
// penalty auto, contact damping ratio 0.02, no element damping), gravity tilted by `angle` about
// +y (downhill −x).  Without any contact damping a settled block at 0.95 μ holds ~1 s, then its
// residual vibration (kinetic energy 3e-9 J after settling) grows by friction-induced flutter
// (×10 in ~0.2 s, fed by the slip) until it breaks away: docs/verification.md.
// `mesh_shift` moves the block's mesh along x against the base's (another alignment of the two
// meshes at the interface).
Scene incline(double angle, double mu, double end, double mesh_shift = 0.0) {
  Scene scene = basic_scene(end);
  scene.materials.push_back(elastic_material(2400, 1e8, 0.2));
  scene.materials[0].contact.friction = mu;
  scene.materials[0].contact.damping = 0.02;
  scene.gravity = g * Vec3(-std::sin(angle), 0, -std::cos(angle));
  scene.bodies.push_back(box_body("base", Vec3(-0.4, -0.4, -0.1), Vec3(0.4, 0.4, 0), 3, 3, 1));
  scene.bodies[0].fixed = true;
  scene.bodies.push_back(box_body("block", Vec3(-0.2 + mesh_shift, -0.2, 0),
                                  Vec3(0.2 + mesh_shift, 0.2, 0.3), 2, 2, 2));
  return scene;
}

// A column of three 0.4 × 0.4 × 0.15 m blocks (2 × 1 × 1 cells each) stacked on incline()'s base
// (3 × 2 × 1 cells here), with its material, friction and gravity; one cell across y in the
// blocks and two in the base keep the run short.  At tanθ =
// 0.665 the column's weight acts 0.15 m downhill of the base's centre, 3/4 of the way to the toe.
// Its stick springs carry the downhill load on every interface; acting at the overlap centroids
// (before they were anchored to material points) they fed a vibration of the blocks that grew
// until the column broke away after ~0.5 s of dynamics, contact damping or not (0.23 m in 2 s
// with 2 %: docs/verification.md).
Scene column(double angle, double mu, double end) {
  Scene scene = incline(angle, mu, end);
  scene.bodies.pop_back();  // incline()'s block
  scene.bodies[0].mesh.box.cells[1] = 2;
  for (int i = 0; i < 3; ++i)
    scene.bodies.push_back(box_body("block " + std::to_string(i + 1), Vec3(-0.2, -0.2, 0.15 * i),
                                    Vec3(0.2, 0.2, 0.15 * (i + 1)), 2, 1, 1));
  return scene;
}

// Runs `scene` to its end; what the block (piece 1) did from `hold_start` on.
HoldResult hold(const Scene& scene, double hold_start) {
  auto sim = quiet_simulation(scene);
  return run_hold(*sim, hold_start);
}

// Settled under local damping 0.8 for `settle` seconds, then undamped until `end`.
Scene settled(Scene scene, double settle) {
  scene.quasi_static.local_damping = 0.8;
  scene.quasi_static.until = settle;
  return scene;
}

}  // namespace

TEST_CASE("static friction holds at τ/μσ = 0.95 for 2 s after settling, a sudden load slides",
          "[verification][quasi_static]") {
  const double mu = 0.7, angle = std::atan(0.95 * mu);  // 33.6°
  const HoldResult held = hold(settled(incline(angle, mu, 2.05), 0.05), 0.05);
  // The same block without settling: the sudden load sets it rattling on the penalty springs and
  // it slides while the normal force swings low.
  const HoldResult sudden = hold(incline(angle, mu, 0.25), 0.05);
  INFO("settled: moved " << held.slid << " m in 2 s (wall " << held.wall
                         << " s); sudden: " << sudden.slid << " m in 0.2 s");
  CHECK(held.slid < 1e-4);
  CHECK(sudden.slid > 5e-4);
  CHECK(held.balance < 1e-3);
}

TEST_CASE("a column of three blocks at τ/μσ = 0.95 holds for 2 s after settling",
          "[verification][quasi_static]") {
  // Settled 0.1 s under local damping, then 2 s of dynamics with 2 % contact damping; the top
  // block (piece 3) moves least freely: it rides on two interfaces.
  const double mu = 0.7, angle = std::atan(0.95 * mu);
  auto sim = quiet_simulation(settled(column(angle, mu, 2.1), 0.1));
  const HoldResult top = run_hold(*sim, 0.1, 3);
  INFO("top block moved " << top.slid << " m in 2 s (wall " << top.wall << " s), balance error "
                          << top.balance);
  CHECK(top.slid < 1e-4);
  CHECK(top.balance < 1e-3);
}

TEST_CASE("sliding on a tilting table starts between 0.995 and 1.005 tanθ = μ",
          "[verification][quasi_static]") {
  // Settled 0.05 s at 2° below the slide angle, tilted at 10°/s to tanθ = ratio·μ under local
  // damping, settled 0.05 s more, then held undamped for 0.3 s.  Above μ the block slides at
  // a = g(sinθ − μcosθ) (0.5 % over: 0.028 m/s², 1.3 mm in 0.3 s).
  const double mu = 0.7, slide = std::atan(mu);
  for (double shift : {0.0, 0.05}) {
    double moved[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
      const double ratio = k == 0 ? 0.995 : 1.005, target = std::atan(ratio * mu);
      const double from = slide - 2 * deg, rate = 10 * deg, tilted = 0.05 + (target - from) / rate;
      Scene scene = settled(incline(from, mu, tilted + 0.35, shift), tilted + 0.05);
      scene.loads.push_back(tilt_load(Vec3(0, 1, 0), rate, target - from, 0.05));
      const HoldResult s = hold(scene, tilted + 0.05);
      moved[k] = s.slid;
      CHECK(s.balance < 1e-3);
    }
    INFO("mesh shift " << shift << " m: at 0.995 μ moved " << moved[0] << " m, at 1.005 μ "
                       << moved[1] << " m in 0.3 s");
    CHECK(moved[0] < 1e-5);
    CHECK(moved[1] > 5e-4);
  }
}
