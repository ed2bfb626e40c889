// Viscous (Lysmer–Kuhlemeyer) absorbing boundary: a P and an S pulse travel down a column held to
// one-dimensional motion and leave through an absorbing base.  The energy left in the column once
// the pulse has passed the base is the reflected energy; the energy ledger must still balance
// (the dashpots' work is `dissipated_boundary`).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>

#include "scene_helpers.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

struct PulseResult {
  double incident = 0.0, remaining = 0.0, absorbed = 0.0, balance_error = 0.0;
  double reflected_fraction() const { return remaining / incident; }
};

// Column 0.01 × 0.01 × L (m), 200 cells along z; every node held to motion along `axis` (P: z,
// S: x); a smooth pulse u(z) = a·sin²(π(z − z0)/w) for |z − z0| < w/2, moving down (v = c·u′),
// runs for `time` with an absorbing base (absorbing = false: a free base for comparison).
PulseResult run_pulse(int axis, bool absorbing) {
  const double L = 2.0, rho = 2000.0, E = 1.0e8, nu = 0.25;
  const LameParameters lame = LameParameters::from_young_poisson(E, nu);
  const double c = axis == 2 ? std::sqrt(lame.p_wave_modulus() / rho) : std::sqrt(lame.mu / rho);
  const double z0 = 1.2, w = 0.4, a = 1e-4;
  // The pulse's tail passes the base at (z0 + w/2)/c; its reflection then needs (z0 + w/2)/c more
  // to reach the top: stop in between.
  const double end_time = 1.5 * (z0 + w / 2) / c;
  Scene scene = basic_scene(end_time);
  scene.materials.push_back(elastic_material(rho, E, nu));
  scene.bodies.push_back(box_body("column", Vec3(0, 0, 0), Vec3(0.01, 0.01, L), 1, 1, 200));
  // One-dimensional motion: the other two components prescribed 0 on every node.
  const unsigned held = 7u & ~(1u << axis);
  scene.loads.push_back(load_on_region(Vec3(-1, -1, -1), Vec3(1, 1, L + 1), Vec3::Zero(), held));
  if (absorbing) {
    AbsorbingSpec base;
    base.region = RegionSpec{Vec3(-1, -1, -1e-6), Vec3(1, 1, 1e-6)};
    scene.absorbing.push_back(base);
  }
  auto sim = quiet_simulation(scene);
  Model& model = sim->model();
  const double pi = std::acos(-1.0);
  for (LocalIndex n = 0; n < model.nodes.size(); ++n) {
    const double z = model.nodes.x0(n)[2], s = (z - z0) / w;
    if (std::abs(s) >= 0.5) continue;
    const double phase = pi * s + pi / 2;  // 0 .. π over the pulse
    const double u = a * std::sin(phase) * std::sin(phase);
    const double du = a * 2 * std::sin(phase) * std::cos(phase) * pi / w;  // du/dz
    model.nodes.x[3 * n + axis] += u;
    model.nodes.v[3 * n + axis] = c * du;  // u(z + ct): moving towards −z
  }
  PulseResult r;
  sim->step();
  const EnergyTerms first = sim->report().energy;
  r.incident = first.kinetic + first.strain;
  while (sim->time() < end_time) sim->step();
  const RunReport report = sim->report();
  r.remaining = report.energy.kinetic + report.energy.strain;
  r.absorbed = report.energy.dissipated_boundary;
  r.balance_error = report.balance_error;
  return r;
}

}  // namespace

TEST_CASE("absorbing base: a P pulse leaves the column, reflected energy < 5 %",
          "[verification][absorbing]") {
  const PulseResult r = run_pulse(2, true);
  const PulseResult free = run_pulse(2, false);
  std::printf(
      "  P pulse: incident %.4e J, left in the column %.4e J (%.3f %%), absorbed %.4e J, "
      "balance error %.2e; free base keeps %.1f %%\n",
      r.incident, r.remaining, 100 * r.reflected_fraction(), r.absorbed, r.balance_error,
      100 * free.reflected_fraction());
  CHECK(r.reflected_fraction() < 0.05);
  CHECK(free.reflected_fraction() > 0.95);  // without the dashpots all of it comes back
  CHECK(r.absorbed == Approx(r.incident - r.remaining).epsilon(0.01));
  CHECK(r.balance_error < 0.01);
}

TEST_CASE("absorbing base: an S pulse leaves the column, reflected energy < 5 %",
          "[verification][absorbing]") {
  const PulseResult r = run_pulse(0, true);
  const PulseResult free = run_pulse(0, false);
  std::printf(
      "  S pulse: incident %.4e J, left in the column %.4e J (%.3f %%), absorbed %.4e J, "
      "balance error %.2e; free base keeps %.1f %%\n",
      r.incident, r.remaining, 100 * r.reflected_fraction(), r.absorbed, r.balance_error,
      100 * free.reflected_fraction());
  CHECK(r.reflected_fraction() < 0.05);
  CHECK(free.reflected_fraction() > 0.95);
  CHECK(r.absorbed == Approx(r.incident - r.remaining).epsilon(0.01));
  CHECK(r.balance_error < 0.01);
}
