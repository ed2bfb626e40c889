// A scalar function of time for loads (docs/scene-format.md, "Time histories"): a constant, a
// table of (time, value) pairs linear between rows, or a smooth step between two values.  A load
// multiplies its magnitude by it (a prescribed velocity, a pressure, a traction) or takes it as
// its value (an acceleration ramp); the value type is the same for every load.
#pragma once

#include <string>
#include <vector>

namespace fdem {

struct TimeHistory {
  enum class Kind { constant, table, smooth_step } kind = Kind::constant;
  // Smooth-step shapes of s = (t − start)/(end − start) in [0, 1]: cubic 3s² − 2s³ (C¹: rate 0
  // at both ends), quintic 10s³ − 15s⁴ + 6s⁵ (C²: acceleration 0 too, no jerk at the ends),
  // sine sin²(πs/2) (C¹, the half-cosine rise).
  enum class Shape { cubic, quintic, sine };

  double value = 1.0;                 // constant
  std::vector<double> times, values;  // table: times (s) increasing, at least two rows
  double start = 0.0, end = 0.0;      // smooth_step: s, start < end
  double from = 0.0, to = 1.0;        // smooth_step: value until start and from end on
  Shape shape = Shape::quintic;
  std::string source;  // where it was given (file and line, or the table's file), for messages

  // Value at time t (s).  A table holds its first value before its first time and its last
  // value after its last time.
  double operator()(double t) const;
  // Whether the value can change in time.
  bool varies() const { return kind != Kind::constant; }
  // The time (s) from which the value stays constant (0 when it never changes; a table's last
  // row whose value differs from the row before; a smooth step's end) and that value.
  double last_change() const;
  double final_value() const;
  // One line for `fdem check`: "constant 1", "table of 4 rows (0 s .. 0.002 s)", ...
  std::string describe() const;

  static TimeHistory constant_value(double v);
  static TimeHistory table(std::vector<double> times, std::vector<double> values);
  static TimeHistory smooth_step(double start, double end, double from, double to,
                                 Shape shape = Shape::quintic);
};

// The smooth-step shape at s (clamped to [0, 1]), from 0 to 1.
double smooth_step_shape(TimeHistory::Shape shape, double s);

}  // namespace fdem
