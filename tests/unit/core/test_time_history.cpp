// core/time_history: tables against linear interpolation and their held ends, the smooth steps
// against their closed forms, their end values and the continuity of their derivatives, and when
// each stops changing.
#include <catch2/catch.hpp>
#include <cmath>

#include "core/time_history.hpp"

using fdem::smooth_step_shape;
using fdem::TimeHistory;

TEST_CASE("time history: a constant, and a table linear between rows, held outside",
          "[core][time_history]") {
  CHECK(TimeHistory()(123.0) == 1.0);
  CHECK(TimeHistory::constant_value(-2.5)(0.0) == -2.5);
  const TimeHistory h = TimeHistory::table({0.1, 0.2, 0.5}, {1.0, 3.0, -3.0});
  CHECK(h.varies());
  CHECK(h(0.0) == 1.0);  // before the first row: its value
  CHECK(h(0.1) == 1.0);
  CHECK(h(0.15) == Approx(2.0).epsilon(1e-14));
  CHECK(h(0.2) == Approx(3.0).epsilon(1e-14));
  CHECK(h(0.35) == Approx(0.0).margin(1e-14));
  CHECK(h(0.45) == Approx(-2.0).epsilon(1e-14));
  CHECK(h(0.5) == -3.0);
  CHECK(h(7.0) == -3.0);  // after the last: its value
  CHECK(h.describe() == "table of 3 rows (0.1 s .. 0.5 s)");
}

TEST_CASE("time history: smooth steps are their polynomials, from `from` to `to`",
          "[core][time_history]") {
  for (double s : {0.0, 0.1, 0.25, 0.5, 0.8, 1.0}) {
    CHECK(smooth_step_shape(TimeHistory::Shape::cubic, s) ==
          Approx(3 * s * s - 2 * s * s * s).margin(1e-15));
    CHECK(smooth_step_shape(TimeHistory::Shape::quintic, s) ==
          Approx(10 * std::pow(s, 3) - 15 * std::pow(s, 4) + 6 * std::pow(s, 5)).margin(1e-15));
    CHECK(smooth_step_shape(TimeHistory::Shape::sine, s) ==
          Approx(0.5 * (1 - std::cos(M_PI * s))).margin(1e-15));
  }
  const TimeHistory q = TimeHistory::smooth_step(2.0, 4.0, 10.0, 30.0);  // quintic by default
  CHECK(q(0.0) == 10.0);
  CHECK(q(2.0) == 10.0);
  CHECK(q(3.0) == Approx(20.0).epsilon(1e-14));  // symmetric: half-way at mid-time
  CHECK(q(4.0) == 30.0);
  CHECK(q(9.0) == 30.0);
  CHECK(q(2.5) == Approx(10.0 + 20.0 * (10 / 64.0 - 15 / 256.0 + 6 / 1024.0)).epsilon(1e-14));
}

TEST_CASE("time history: a cubic step starts and ends at rest, a quintic without jerk either",
          "[core][time_history]") {
  // One-sided differences at the ends of the step (over [0, 1]): the cubic's slope vanishes like
  // h, its curvature does not (6); the quintic's slope like h² and its curvature like h.
  const double h = 1e-4;
  const auto slope = [&](TimeHistory::Shape shape, double s) {
    return (smooth_step_shape(shape, s + h) - smooth_step_shape(shape, s)) / h;
  };
  const auto curvature = [&](TimeHistory::Shape shape, double s) {
    return (smooth_step_shape(shape, s + 2 * h) - 2 * smooth_step_shape(shape, s + h) +
            smooth_step_shape(shape, s)) /
           (h * h);
  };
  using Shape = TimeHistory::Shape;
  CHECK(std::abs(slope(Shape::cubic, 0.0)) < 4 * h);
  CHECK(std::abs(slope(Shape::cubic, 1.0 - h)) < 4 * h);
  CHECK(curvature(Shape::cubic, 0.0) == Approx(6.0).epsilon(1e-3));
  CHECK(std::abs(slope(Shape::quintic, 0.0)) < 20 * h * h);
  CHECK(std::abs(curvature(Shape::quintic, 0.0)) < 100 * h);
  CHECK(std::abs(curvature(Shape::quintic, 1.0 - 2 * h)) < 100 * h);
  CHECK(std::abs(slope(Shape::sine, 0.0)) < 4 * h);
  // The largest slope: 1.5 (cubic), 1.875 (quintic), π/2 (sine), at mid-step.
  CHECK(slope(Shape::cubic, 0.5 - h / 2) == Approx(1.5).epsilon(1e-6));
  CHECK(slope(Shape::quintic, 0.5 - h / 2) == Approx(1.875).epsilon(1e-6));
  CHECK(slope(Shape::sine, 0.5 - h / 2) == Approx(M_PI / 2).epsilon(1e-6));
}

TEST_CASE("time history: when it stops changing, and at what value", "[core][time_history]") {
  const TimeHistory constant = TimeHistory::constant_value(2.0);
  CHECK(constant.last_change() == 0.0);
  CHECK(constant.final_value() == 2.0);
  // A table's last change is the last row whose value differs from the row before.
  const TimeHistory table = TimeHistory::table({0.0, 0.1, 0.3, 0.6}, {0.0, 1.0, 0.5, 0.5});
  CHECK(table.last_change() == 0.3);
  CHECK(table.final_value() == 0.5);
  CHECK(table(0.3) == table(0.6));
  CHECK(TimeHistory::table({0.2, 0.4}, {1.0, 1.0}).last_change() == 0.0);  // never changes
  const TimeHistory step = TimeHistory::smooth_step(0.1, 0.4, 0.0, 3.0);
  CHECK(step.last_change() == 0.4);
  CHECK(step.final_value() == 3.0);
  CHECK(TimeHistory::smooth_step(0.1, 0.4, 1.0, 1.0).last_change() == 0.0);
}
