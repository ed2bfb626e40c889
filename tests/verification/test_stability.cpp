// The automatic time step against the stability limit found by bisection on distorted meshes.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "core/error.hpp"
#include "scene_helpers.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

Scene distorted_scene() {
  Scene scene = basic_scene(1.0);
  scene.materials.push_back(elastic_material(2500, 30e9, 0.25));
  scene.bodies.push_back(box_body("block", Vec3(0, 0, 0), Vec3(1, 1, 1), 4, 4, 4));
  scene.time.safety = 0.95;
  return scene;
}

// Moves interior nodes of the model randomly (reference configuration) and rebuilds the model.
std::unique_ptr<Simulation> distorted_simulation(unsigned seed, double distortion, double dt = 0) {
  Scene scene = distorted_scene();
  BodyMesh mesh = box_mesh(scene.bodies[0].mesh.box);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const double h = 0.25;
  for (std::size_t n = 0; n < mesh.coords.size() / 3; ++n) {
    bool interior = true;
    for (int k = 0; k < 3; ++k)
      interior &= mesh.coords[3 * n + k] > 0 && mesh.coords[3 * n + k] < 1;
    if (interior)
      for (int k = 0; k < 3; ++k) mesh.coords[3 * n + k] += distortion * h * u(rng);
  }
  Model model = build_model(scene, {mesh});
  const RunOptions options = quiet_options();
  auto sim = std::make_unique<Simulation>(scene, std::move(model), options);
  // Seed every mode with a small random velocity.
  std::normal_distribution<double> g(0.0, 1e-3);
  for (double& v : sim->model().nodes.v) v = g(rng);
  if (dt > 0) sim->set_time_step(dt);
  return sim;
}

// Half-step kinetic energy ½m|v_n+½|² plus strain energy: grows without bound in an unstable run
// (the modified energy ½m·v⁻·v⁺ + U does not: central difference conserves it even then).
double plain_energy(const Simulation& sim) {
  const NodeArrays& nodes = sim.model().nodes;
  double k = 0;
  for (LocalIndex n = 0; n < nodes.size(); ++n)
    k += 0.5 * nodes.mass[n] * vec3_at(nodes.v.data(), n).squaredNorm();
  return k + sim.energy().current().strain;
}

// Stable: 3000 steps with bounded energy (no NumericalFailure, energy not grown 10x).
bool stable(unsigned seed, double distortion, double dt) {
  auto sim = distorted_simulation(seed, distortion, dt);
  try {
    sim->step();
    const double e0 = plain_energy(*sim);
    for (int i = 0; i < 3000; ++i) {
      sim->step();
      if (!(plain_energy(*sim) < 10 * e0)) return false;
    }
  } catch (const NumericalFailure&) {
    return false;
  }
  return true;
}

}  // namespace

TEST_CASE("automatic step lies between half of and just under the bisected stability limit",
          "[verification]") {
  for (auto [seed, distortion] : {std::pair<unsigned, double>{1, 0.0}, {2, 0.15}, {3, 0.3}}) {
    auto sim = distorted_simulation(seed, distortion);
    const double auto_step = sim->time_step();  // 0.95 × element bound
    double lo = auto_step, hi = 3 * auto_step;
    REQUIRE(stable(seed, distortion, lo));
    REQUIRE(!stable(seed, distortion, hi));
    for (int i = 0; i < 10; ++i) {
      const double mid = 0.5 * (lo + hi);
      (stable(seed, distortion, mid) ? lo : hi) = mid;
    }
    INFO("distortion " << distortion << ": auto step " << auto_step << " s, bisected limit " << lo
                       << " s, ratio " << auto_step / lo);
    CHECK(auto_step >= 0.5 * lo);
    CHECK(auto_step < lo);
  }
}

TEST_CASE("a run above the stability limit is stopped and reported as unstable", "[verification]") {
  auto sim = distorted_simulation(2, 0.15);
  sim->set_time_step(2.5 * sim->critical_time_step());
  try {
    for (int i = 0; i < 20000; ++i) sim->step();
    FAIL("the unstable run was not stopped");
  } catch (const NumericalFailure& failure) {
    const std::string msg = failure.what();
    CHECK_THAT(msg, Catch::Contains("step"));
    CHECK_THAT(msg, Catch::Contains("critical step"));
    CHECK((msg.find("unstable") != std::string::npos || msg.find("inverted") != std::string::npos));
  }
  // Nothing became NaN before the stop.
  for (double x : sim->model().nodes.x) REQUIRE(std::isfinite(x));
}

TEST_CASE("a stable run at 0.95 of the critical step is not stopped", "[verification]") {
  // Free–free axial vibration of a slender beam: the highest modes sit near ωΔt = 1.9, where the
  // conserved kinetic term ½m·v⁻·v⁺ is negative on average; the run is stable and must go on.
  Scene scene = basic_scene(1.0);
  scene.materials.push_back(elastic_material(2500, 30e9, 0.0, ElasticModel::st_venant_kirchhoff));
  scene.bodies.push_back(box_body("beam", Vec3(0, 0, 0), Vec3(2.0, 0.1, 0.1), 20, 1, 1));
  scene.time.safety = 0.95;
  auto sim = quiet_simulation(scene);
  NodeArrays& nodes = sim->model().nodes;
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 1e-3);
  for (LocalIndex n = 0; n < nodes.size(); ++n) {
    nodes.v[3 * n] = 0.01 * std::cos(M_PI * nodes.x0(n)[0] / 2.0);
    for (int k = 0; k < 3; ++k) nodes.v[3 * n + k] += g(rng);  // every mode, the highest included
  }
  double worst = 0;
  REQUIRE_NOTHROW([&] {
    for (int i = 0; i < 5000; ++i) {
      sim->step();
      worst = std::max(worst, sim->energy().balance_error());
    }
  }());
  INFO("worst balance error " << worst);
  CHECK(worst < 1e-3);
}
