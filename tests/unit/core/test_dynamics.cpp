// The central-difference update with Cundall's local damping: the closed-form decay of a linear
// oscillator, an exact energy balance, and no effect on prescribed components or nodes at rest.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "core/dynamics.hpp"
#include "core/energy.hpp"

using namespace fdem;

namespace {

// One free node of mass m on a spring k along x, released from x = 0 at speed v0.
NodeArrays one_node(double m, double v0) {
  NodeArrays nodes;
  nodes.resize(1);
  nodes.n_owned = 1;
  nodes.mass[0] = m;
  nodes.v[0] = v0;
  return nodes;
}

}  // namespace

TEST_CASE("local damping: a linear oscillator's turning points shrink by √((1−α)/(1+α))",
          "[dynamics][quasi_static]") {
  // With f_d = −α|f|sign(v) the spring is (1+α)k while the node moves away from rest and (1−α)k
  // while it comes back, so each half cycle keeps (1−α)/(1+α) of the energy: the amplitude of
  // successive turning points falls by r = √((1−α)/(1+α)) whatever m and k.
  const double m = 2.0, k = 50.0, alpha = 0.3, v0 = 1.5;
  const double omega = std::sqrt(k / m), dt = 1e-4 / omega;
  const double ratio = std::sqrt((1 - alpha) / (1 + alpha));
  NodeArrays nodes = one_node(m, v0);
  WorkAccumulator damping;
  double dissipated = 0.0, worst_balance = 0.0;
  const double e0 = 0.5 * m * v0 * v0;
  std::vector<double> turning;
  double previous_v = v0;
  for (int s = 0; s < 400000 && turning.size() < 6; ++s) {
    const double x = nodes.x[0];
    nodes.f.assign(3, 0.0);
    nodes.f[0] = -k * x;
    const IntegrationSummary step = integrate_central_difference(dt, nodes, alpha);
    // Balance at t_n: ½m·v⁻·v⁺ + ½kx² + dissipated = E0 (spring work by the trapezoid is exact).
    dissipated = -damping.add(step.local_damping_work_before, step.local_damping_work_after);
    if (s > 0)
      worst_balance = std::max(
          worst_balance, std::abs(step.kinetic_energy + 0.5 * k * x * x + dissipated - e0) / e0);
    if ((previous_v > 0) != (nodes.v[0] > 0)) turning.push_back(std::abs(nodes.x[0]));
    previous_v = nodes.v[0];
  }
  REQUIRE(turning.size() == 6);
  // The first turning point: ½m·v0² = ½(1+α)k·A².
  CHECK(turning[0] == Approx(v0 * std::sqrt(m / ((1 + alpha) * k))).epsilon(1e-3));
  for (std::size_t i = 1; i < turning.size(); ++i) {
    INFO("turning point " << i << ": " << turning[i] << " m after " << turning[i - 1]);
    CHECK(turning[i] / turning[i - 1] == Approx(ratio).epsilon(1e-3));
  }
  CHECK(worst_balance < 1e-12);
  CHECK(dissipated > 0.9 * e0);  // six half cycles keep r^12 = 2 % of it
}

TEST_CASE("local damping: nothing on prescribed components or nodes at rest, α = 0 is plain",
          "[dynamics][quasi_static]") {
  NodeArrays damped = one_node(1.0, 0.0);
  damped.v[1] = 0.5;
  damped.v[2] = -0.25;
  damped.constrained[0] = 4;  // z prescribed
  damped.prescribed_velocity[2] = -0.25;
  NodeArrays plain = damped;
  for (NodeArrays* nodes : {&damped, &plain}) nodes->f = {3.0, -2.0, 7.0};
  const IntegrationSummary d = integrate_central_difference(1e-3, damped, 0.8);
  const IntegrationSummary p = integrate_central_difference(1e-3, plain, 0.0);
  CHECK(damped.v[0] == plain.v[0]);  // at rest: no damping, the force accelerates it fully
  CHECK(damped.v[2] == -0.25);       // prescribed
  // Moving in +y against f_y = −2: the damping adds 0.8·2 N against the motion.
  CHECK(damped.v[1] == Approx(0.5 + 1e-3 * (-2.0 - 1.6)).epsilon(1e-14));
  CHECK(plain.v[1] == Approx(0.5 + 1e-3 * -2.0).epsilon(1e-14));
  CHECK(d.local_damping_work_before == Approx(0.5 * 1e-3 * -1.6 * 0.5));
  CHECK(p.local_damping_work_before == 0.0);
  CHECK(p.local_damping_work_after == 0.0);
}
