// Energy bookkeeping: the trapezoid work of a force (WorkAccumulator) and the ledger's balance,
// exact for central difference under a constant force and a linear spring.
#include <catch2/catch.hpp>
#include <cmath>

#include "core/dynamics.hpp"
#include "core/energy.hpp"

using namespace fdem;

TEST_CASE(
    "work accumulator and ledger: a mass on a spring under a constant force balances to "
    "round-off",
    "[energy]") {
  const double m = 2.0, k = 800.0, force = 3.0;  // kg, N/m, N
  const double dt = 0.5 * 2.0 / std::sqrt(k / m);
  NodeArrays nodes;
  nodes.resize(1);
  nodes.n_owned = 1;
  nodes.mass[0] = m;
  nodes.v[0] = 0.4;  // m/s: v(−dt/2), taken as given
  EnergyLedger ledger;
  double largest_error = 0.0, work = 0.0;
  double x_previous = nodes.x[0];
  for (int n = 0; n < 20000; ++n) {
    const double x = nodes.x[0];
    nodes.f[0] = force - k * x;
    const double before = 0.5 * force * (x - x_previous);
    const IntegrationSummary motion = integrate_central_difference(dt, nodes);
    const double after = 0.5 * force * (nodes.x[0] - x);
    EnergyTerms terms;
    terms.kinetic = motion.kinetic_energy;  // ½m·v_n−½·v_n+½
    terms.strain = 0.5 * k * x * x;
    terms.external_work = ledger.external.add(before, after);
    work = terms.external_work;
    ledger.record(terms);
    largest_error = std::max(largest_error, ledger.balance_error());
    x_previous = x;
  }
  CHECK(std::abs(work) > 1e-3);  // the force did work (J), in and out as the mass swings
  CHECK(largest_error < 1e-12);

  // A joule that goes nowhere is seen: the error is measured against the largest term.
  EnergyTerms lost = ledger.current();
  lost.kinetic -= 1e-3 * lost.scale();
  ledger.record(lost);
  CHECK(ledger.balance_error() > 1e-4);
  CHECK(ledger.balance_error() <= 1e-3 * (1.0 + 1e-9));
}

TEST_CASE("work accumulator: constant power P gives P·t_n at every step, halves or not",
          "[energy]") {
  WorkAccumulator w;
  const double power = 7.0, dt = 0.25;  // W, s
  for (int n = 0; n < 100; ++n)
    CHECK(w.add(0.5 * power * dt, 0.5 * power * dt) == Approx(power * n * dt));
  // The first "before" half covers time before t_0: it is not counted.
  WorkAccumulator first;
  CHECK(first.add(5.0, 1.0) == 0.0);
  CHECK(first.add(2.0, 2.0) == Approx(3.0));
}
