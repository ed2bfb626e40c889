#include "core/time_history.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace fdem {

double smooth_step_shape(TimeHistory::Shape shape, double s) {
  s = std::clamp(s, 0.0, 1.0);
  switch (shape) {
    case TimeHistory::Shape::cubic:
      return s * s * (3.0 - 2.0 * s);
    case TimeHistory::Shape::quintic:
      return s * s * s * (10.0 + s * (-15.0 + 6.0 * s));
    case TimeHistory::Shape::sine: {
      const double h = std::sin(0.5 * M_PI * s);
      return h * h;
    }
  }
  return s;
}

double TimeHistory::operator()(double t) const {
  switch (kind) {
    case Kind::constant:
      return value;
    case Kind::table: {
      if (t <= times.front()) return values.front();
      if (t >= times.back()) return values.back();
      // First row after t; rows are few (tens to thousands), a binary search is plenty.
      const auto it = std::upper_bound(times.begin(), times.end(), t);
      const std::size_t i = static_cast<std::size_t>(it - times.begin());
      const double w = (t - times[i - 1]) / (times[i] - times[i - 1]);
      return values[i - 1] + w * (values[i] - values[i - 1]);
    }
    case Kind::smooth_step:
      return from + (to - from) * smooth_step_shape(shape, (t - start) / (end - start));
  }
  return value;
}

double TimeHistory::last_change() const {
  switch (kind) {
    case Kind::constant:
      return 0.0;
    case Kind::table: {
      std::size_t i = values.size() - 1;
      while (i > 0 && values[i - 1] == values[i]) --i;
      return i == 0 ? 0.0 : times[i];  // all rows equal: constant
    }
    case Kind::smooth_step:
      return from == to ? 0.0 : end;
  }
  return 0.0;
}

double TimeHistory::final_value() const {
  switch (kind) {
    case Kind::constant:
      return value;
    case Kind::table:
      return values.back();
    case Kind::smooth_step:
      return to;
  }
  return value;
}

std::string TimeHistory::describe() const {
  std::ostringstream out;
  out.precision(6);
  switch (kind) {
    case Kind::constant:
      out << "constant " << value;
      break;
    case Kind::table:
      out << "table of " << times.size() << " rows (" << times.front() << " s .. " << times.back()
          << " s)";
      break;
    case Kind::smooth_step:
      out << (shape == Shape::cubic     ? "cubic"
              : shape == Shape::quintic ? "quintic"
                                        : "sine")
          << " smooth step " << from << " -> " << to << " over " << start << " s .. " << end
          << " s";
      break;
  }
  return out.str();
}

TimeHistory TimeHistory::constant_value(double v) {
  TimeHistory h;
  h.value = v;
  return h;
}

TimeHistory TimeHistory::table(std::vector<double> t, std::vector<double> v) {
  TimeHistory h;
  h.kind = Kind::table;
  h.times = std::move(t);
  h.values = std::move(v);
  return h;
}

TimeHistory TimeHistory::smooth_step(double start, double end, double from, double to,
                                     Shape shape) {
  TimeHistory h;
  h.kind = Kind::smooth_step;
  h.start = start;
  h.end = end;
  h.from = from;
  h.to = to;
  h.shape = shape;
  return h;
}

}  // namespace fdem
