// When the next row or frame of an output series is due.
#pragma once

#include <cmath>

namespace fdem {

// The first of next, next + every, next + 2 every, ... after `now` (s).  Many intervals within
// one step are skipped at once (the scene reader guarantees every ≥ 1e-12 time.end, so that
// next + every > next); the same sums as adding `every` one at a time when they are few.
inline double next_output_time(double next, double now, double every) {
  if (next <= now) {
    const double skipped = std::floor((now - next) / every);
    if (skipped > 16) next += (skipped - 1) * every;
  }
  while (next <= now) next += every;
  return next;
}

}  // namespace fdem
