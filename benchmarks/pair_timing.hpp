// Timing one pair evaluation alone, shared by the benchmarks that print per-pair cost
// distributions (bench_contact_pair, bench_contact_scene_pairs).
#pragma once

#include <algorithm>
#include <chrono>
#include <ctime>

namespace fdem::bench {

// ns per call of `body` (which returns a double, added to `sink` so that the calls stay): the
// best of 3 batches of 8 calls on the steady clock, so that one interruption does not count.
template <class Body>
double best_of_batches_ns(Body body, double& sink) {
  using Clock = std::chrono::steady_clock;
  double best = 1e30;
  for (int batch = 0; batch < 3; ++batch) {
    const auto start = Clock::now();
    for (int rep = 0; rep < 8; ++rep) sink += body();
    best = std::min(best, std::chrono::duration<double>(Clock::now() - start).count() / 8);
  }
  return 1e9 * best;
}

// This thread's CPU time (s).
inline double thread_cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace fdem::bench
