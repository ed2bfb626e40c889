// Timing one pair evaluation alone, shared by the benchmarks that print per-pair cost
// distributions (bench_contact_pair, bench_contact_scene_pairs).
#pragma once

#include <algorithm>
#include <chrono>

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

}  // namespace fdem::bench
