// Kinetic damping in the central-difference update (core/dynamics): a linear oscillator stops at
// its equilibrium at the first peak of its kinetic energy, two modes lose their energy stop by
// stop, a motion that keeps speeding up is never touched, prescribed components keep their
// velocity, and the energy balance stays exact.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include "core/dynamics.hpp"
#include "core/energy.hpp"

using namespace fdem;

namespace {

NodeArrays resting_node(double m, const Vec3& x) {
  NodeArrays nodes;
  nodes.resize(1);
  nodes.n_owned = 1;
  nodes.mass[0] = m;
  for (int k = 0; k < 3; ++k) nodes.x[k] = x[k];
  return nodes;
}

// Steps one node on springs k[c] along each axis (or a constant force when `force` is given),
// deciding kinetic damping's stops as the driver does, and keeps the energy balance at t_n:
// ½m·v⁻·v⁺ + ½Σk·x² + dissipated = E0 (the trapezoid work of the springs is exact).
struct KineticRun {
  KineticRun(NodeArrays start, const Vec3& springs) : nodes(std::move(start)), k(springs) {}
  NodeArrays nodes;
  Vec3 k;
  double e0 = 0.0, dissipated = 0.0, worst_balance = 0.0;
  double kinetic_before = 0.0;
  bool stop = false;
  std::vector<long> stops;  // steps that stopped the node
  WorkAccumulator damping_work;

  double potential() const {
    double e = 0.0;
    for (int c = 0; c < 3; ++c) e += 0.5 * k[c] * nodes.x[c] * nodes.x[c];
    return e;
  }
  void step(long s, double dt) {
    const double potential_n = potential();
    for (int c = 0; c < 3; ++c) nodes.f[c] = -k[c] * nodes.x[c];
    const IntegrationSummary r =
        integrate_central_difference(dt, nodes, StepDamping{true, 0.0, stop});
    if (stop) stops.push_back(s);
    dissipated = -damping_work.add(r.damping_work_before, r.damping_work_after);
    if (s > 0)
      worst_balance =
          std::max(worst_balance, std::abs(r.kinetic_energy + potential_n + dissipated - e0) / e0);
    stop = kinetic_energy_peaked(kinetic_before, r.kinetic_energy_half_step, stop);
    kinetic_before = r.kinetic_energy_half_step;
  }
};

}  // namespace

TEST_CASE(
    "kinetic damping: an oscillator released from rest stops at its equilibrium after a "
    "quarter period, with an exact energy balance",
    "[dynamics][quasi_static]") {
  const double m = 2.0, stiffness = 50.0, x0 = 0.1;
  const double omega = std::sqrt(stiffness / m), dt = 1e-3 / omega;
  KineticRun run{resting_node(m, Vec3(x0, 0, 0)), Vec3(stiffness, 0, 0)};
  run.e0 = run.potential();
  for (long s = 0; s < 20000; ++s) run.step(s, dt);
  REQUIRE(run.stops.size() >= 1);
  // The energy peaks at x = 0, a quarter period (π/2)/(ω·dt) = 1571 steps in; the stop comes the
  // step after the step that saw the energy fall, and each step moves the node ≤ ω·x0·dt.
  CHECK(std::abs(run.stops[0] - 0.5 * M_PI / (omega * dt)) <= 3.0);
  const double speed = omega * x0;  // m/s, the largest
  // After the first stop what is left oscillates about 0 with |x| ≤ 3 steps' travel.
  double worst_after = 0.0;
  KineticRun again{resting_node(m, Vec3(x0, 0, 0)), Vec3(stiffness, 0, 0)};
  again.e0 = again.potential();
  for (long s = 0; s < 20000; ++s) {
    again.step(s, dt);
    if (s > run.stops[0]) worst_after = std::max(worst_after, std::abs(again.nodes.x[0]));
  }
  CHECK(worst_after <= 3.0 * speed * dt);
  CHECK(worst_after < 1e-2 * x0);
  CHECK(run.dissipated == Approx(run.e0).epsilon(1e-4));  // all of it, to (3ω·dt)²
  CHECK(run.worst_balance < 1e-12);
}

TEST_CASE("kinetic damping: two modes lose their energy stop by stop", "[dynamics][quasi_static]") {
  // Two springs 1 : 7.3 along x and y, both released from rest: the stops come at the peaks of
  // the sum of their kinetic energies, and each stop takes what either mode has.
  const double m = 1.0, k1 = 40.0;
  const double omega_max = std::sqrt(7.3 * k1 / m), dt = 1e-2 / omega_max;
  KineticRun run{resting_node(m, Vec3(0.1, 0.1, 0)), Vec3(k1, 7.3 * k1, 0)};
  run.e0 = run.potential();
  const long steps = 40 * static_cast<long>(2 * M_PI * std::sqrt(m / k1) / dt);  // 40 slow periods
  for (long s = 0; s < steps; ++s) run.step(s, dt);
  INFO(run.stops.size() << " stops, energy left " << run.potential() / run.e0);
  CHECK(run.stops.size() >= 4);
  CHECK(run.potential() < 1e-6 * run.e0);
  CHECK(run.worst_balance < 1e-12);
}

TEST_CASE("kinetic damping never stops a motion that keeps speeding up",
          "[dynamics][quasi_static]") {
  // A constant force (a mechanism under its load): the kinetic energy only grows, so no stop,
  // and the state is the undamped step's bit for bit.
  NodeArrays damped = resting_node(3.0, Vec3(0, 0, 1));
  NodeArrays plain = damped;
  double before = 0.0;
  bool stop = false;
  for (int s = 0; s < 1000; ++s) {
    for (NodeArrays* nodes : {&damped, &plain}) nodes->f = {0.0, 1.5, -29.43};
    const IntegrationSummary r =
        integrate_central_difference(1e-4, damped, StepDamping{true, 0.0, stop});
    integrate_central_difference(1e-4, plain);
    REQUIRE_FALSE(stop);
    stop = kinetic_energy_peaked(before, r.kinetic_energy_half_step, stop);
    before = r.kinetic_energy_half_step;
  }
  CHECK(std::memcmp(damped.x.data(), plain.x.data(), 3 * sizeof(double)) == 0);
  CHECK(std::memcmp(damped.v.data(), plain.v.data(), 3 * sizeof(double)) == 0);
  CHECK(damped.v[2] == Approx(-29.43 / 3.0 * 1000 * 1e-4));
}

TEST_CASE(
    "kinetic damping: a stop leaves free components at rest where they are, prescribed ones "
    "at their velocity, and its work is the kinetic energy it takes",
    "[dynamics][quasi_static]") {
  NodeArrays nodes = resting_node(2.0, Vec3(1, 2, 3));
  nodes.v = {0.5, -0.25, 0.75};
  nodes.f = {4.0, 6.0, -8.0};
  nodes.constrained[0] = 4;  // z prescribed
  nodes.prescribed_velocity[2] = 0.75;
  const double dt = 1e-3;
  const IntegrationSummary r =
      integrate_central_difference(dt, nodes, StepDamping{true, 0.0, true});
  CHECK(nodes.v[0] == 0.0);
  CHECK(nodes.v[1] == 0.0);
  CHECK(nodes.v[2] == 0.75);
  CHECK(nodes.x[0] == 1.0);
  CHECK(nodes.x[1] == 2.0);
  CHECK(nodes.x[2] == Approx(3.0 + 0.75 * dt));
  // The stopping force −m·v_raw/dt (v_raw = v⁻ + dt·f/m) works ½dt·f·v⁻ before t_n, 0 after.
  const double raw_x = 0.5 + dt * 4.0 / 2.0, raw_y = -0.25 + dt * 6.0 / 2.0;
  CHECK(r.damping_work_before == Approx(-0.5 * 2.0 * (raw_x * 0.5 + raw_y * -0.25)));
  CHECK(r.damping_work_after == 0.0);
  CHECK(r.kinetic_energy == Approx(0.5 * 2.0 * 0.75 * 0.75));  // only the prescribed component
  CHECK(r.unbalanced_force == Approx(4.0 + 6.0));
  CHECK(r.support_force == Approx(8.0));
}
