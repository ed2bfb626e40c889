// Initial (in-situ) stress: a geostatic column (σ_v = −ρ g depth, σ_h = K0 σ_v) on a fixed base
// with rollers on its sides, under the gravity that made the stress, is in equilibrium at t = 0
// and stays at rest; without the initial stress it sinks under its weight.  A uniform stress in a
// free body is not in equilibrium at its surface, which the residual reports.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>

#include "scene_helpers.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

const double H = 4.0, rho = 2000.0, g = 9.81;

// A 1 × 1 × H m column (2 × 2 × 8 cells): base fixed, sides on rollers.
Scene column(bool geostatic, double k0) {
  Scene scene = basic_scene(1.0);
  scene.gravity = Vec3(0, 0, -g);
  scene.materials.push_back(elastic_material(rho, 5e8, 0.25));
  scene.bodies.push_back(box_body("column", Vec3(0, 0, 0), Vec3(1, 1, H), 2, 2, 8));
  const double e = 1e-6;
  scene.loads.push_back(load_on_region(Vec3(-1, -1, -e), Vec3(2, 2, e), Vec3::Zero(), 7));
  for (double x : {0.0, 1.0}) {
    scene.loads.push_back(
        load_on_region(Vec3(x - e, -1, -1), Vec3(x + e, 2, H + 1), Vec3::Zero(), 1));
    scene.loads.push_back(
        load_on_region(Vec3(-1, x - e, -1), Vec3(2, x + e, H + 1), Vec3::Zero(), 2));
  }
  if (geostatic) {
    InitialStressSpec s;
    s.kind = InitialStressSpec::Kind::geostatic;
    s.surface = H;
    s.k0 = k0;
    scene.initial_stress.push_back(s);
  }
  return scene;
}

double max_speed(const Model& model) {
  double v = 0.0;
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    v = std::max(v, vec3_at(model.nodes.v.data(), n).norm());
  return v;
}

}  // namespace

TEST_CASE("geostatic initial stress: the column under gravity stays at rest",
          "[verification][initial_stress]") {
  const int steps = 2000;
  for (double k0 : {0.5, 1.0 / 3.0, 1.2}) {
    auto sim = quiet_simulation(column(true, k0));
    const double residual = sim->initial_equilibrium_residual();
    for (int i = 0; i < steps; ++i) sim->step();
    const double v = max_speed(sim->model());
    const RunReport r = sim->report();
    std::printf(
        "  K0 %.3f: equilibrium residual at t = 0 %.2e; after %d steps (%.3g s) max |v| = "
        "%.2e m/s, strain energy %.3g J\n",
        k0, residual, steps, sim->time(), v, r.energy.strain);
    CHECK(residual < 1e-12);
    // Round-off only: g·t would be ~0.1 m/s; sinking without the stress ~1e-3 m/s (below).
    CHECK(v < 1e-9);
  }
  auto bare = quiet_simulation(column(false, 0.5));
  for (int i = 0; i < steps; ++i) bare->step();
  const double v = max_speed(bare->model());
  std::printf("  without initial stress: max |v| = %.2e m/s after %d steps\n", v, steps);
  CHECK(v > 1e-4);
}

TEST_CASE("initial stress: the stress is the tets' and the residual reports imbalance",
          "[initial_stress]") {
  // A uniform stress in a body with free faces is not in equilibrium: only its surface nodes feel
  // a force (the interior ones balance), so the residual is the whole of the stress's forces.
  Scene scene = column(false, 0.5);
  scene.loads.clear();
  InitialStressSpec s;
  s.kind = InitialStressSpec::Kind::uniform;
  const double stress[6] = {-1e5, -2e5, -3e5, 1e4, 2e4, 3e4};
  std::copy(stress, stress + 6, s.stress);
  scene.initial_stress.push_back(s);
  scene.gravity = Vec3::Zero();
  auto sim = quiet_simulation(scene);
  CHECK(sim->initial_equilibrium_residual() == Approx(1.0).epsilon(1e-9));
  // The internal nodes are balanced; the free body springs to the state of zero total stress:
  // after some steps the body has moved and the energy balance still holds (S0:E in strain).
  for (int i = 0; i < 500; ++i) sim->step();
  const RunReport r = sim->report();
  std::printf("  uniform stress, free body: residual %.3f, balance error %.2e, kinetic %.3g J\n",
              sim->initial_equilibrium_residual(), r.balance_error, r.energy.kinetic);
  CHECK(r.energy.kinetic > 0.0);
  CHECK(r.balance_error < 1e-3);
}
