// Per-pair cost of the contact stage as it runs, for benchmarks/contact_pair_timing/run.py: the
// patches there include this header in a copy of contact/contact_stage.cpp (of the commit being
// measured and of issue 12's start) and time every candidate pair's evaluation in the stage's
// loop, friction and dashpot included.  Not part of the engine's build.
//
// Each pair's time (steady clock, ns, the probe's own cost measured and subtracted at the end)
// goes with its outcome and its normal force into a buffer; at the end of each add_forces the
// step's pairs are classed against the step's largest pair normal force and added to
// histograms.  At exit the histograms go to the CSV named by FDEM_PAIR_TIMING.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace fdem::pair_timing {

enum Outcome { kKeptApart = 0, kApart = 1, kOverlapping = 2 };

struct Sample {
  double ns;
  double normal_force;  // N, as the stage found it (0 apart or left out)
  int outcome;
  int slot_a = -1, slot_b = -1;  // where the stage keeps the pair's tets (for `exact` below)
  double penalty = 0.0;          // Pa
};

// Classes, by the exact overlap (every piece integrated): 0 kept apart (not evaluated: apart),
// 1 evaluated and apart, 2 overlapping with a normal force below 1e-6 of the step's largest,
// 3 overlapping and carrying load (at least 1e-6 of the step's largest).  A stage that leaves
// pairs out under a tolerance passes `exact` to end_step, so that a pair it left out is classed by
// its exact overlap, not by what the stage computed.
constexpr int kClasses = 4;
constexpr int kBins = 400;  // log-spaced from 1 ns to 1 ms, 80 per decade

struct Probe {
  std::vector<Sample> step;
  std::vector<double> histogram[kClasses];
  double sum_ns[kClasses] = {0, 0, 0, 0};
  long long count[kClasses] = {0, 0, 0, 0};
  long long steps = 0;
  double overhead_ns = 0.0;
  double shared_ns = 0.0;  // the stage's per-tet work outside the pair loop (geometry, boxes)
  const char* path = std::getenv("FDEM_PAIR_TIMING");

  Probe() {
    for (auto& h : histogram) h.assign(kBins, 0.0);
    // The probe's own cost: two clock reads and a push, timed back to back.
    std::vector<Sample> scratch;
    scratch.reserve(1 << 16);
    double best = 1e30;
    for (int batch = 0; batch < 5; ++batch) {
      scratch.clear();
      const auto start = std::chrono::steady_clock::now();
      for (int i = 0; i < 20000; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        const auto t1 = std::chrono::steady_clock::now();
        scratch.push_back({std::chrono::duration<double, std::nano>(t1 - t0).count(), 0.0, 0});
      }
      const double total =
          std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start)
              .count();
      best = std::min(best, total / 20000.0);
    }
    overhead_ns = best;
  }

  // exact(sample): the pair's exact normal force (N), negative when apart; untimed.
  template <class Exact>
  void end_step(Exact exact) {
    for (Sample& s : step) {
      if (s.outcome == kKeptApart) continue;
      const double f = exact(s);
      s.outcome = f >= 0.0 ? kOverlapping : kApart;
      s.normal_force = std::max(f, 0.0);
    }
    end_step();
  }

  void end_step() {
    if (step.empty()) return;
    double largest = 0.0;
    for (const Sample& s : step) largest = std::max(largest, s.normal_force);
    for (const Sample& s : step) {
      const int c = s.outcome == kKeptApart            ? 0
                    : s.outcome == kApart              ? 1
                    : s.normal_force >= 1e-6 * largest ? 3
                                                       : 2;
      const double ns = std::max(s.ns - overhead_ns, 0.5);
      const int bin = std::clamp(static_cast<int>(std::floor(80.0 * std::log10(ns))), 0, kBins - 1);
      histogram[c][bin] += 1.0;
      sum_ns[c] += ns;
      ++count[c];
    }
    ++steps;
    step.clear();
  }

  ~Probe() {
    if (!path) return;
    std::FILE* f = std::fopen(path, "w");
    if (!f) return;
    std::fprintf(f,
                 "# steps %lld, probe overhead %.1f ns per pair (subtracted), per-tet work outside "
                 "the pair loop %.6f s in all\n",
                 steps, overhead_ns, 1e-9 * shared_ns);
    std::fprintf(f, "class,count,mean_ns,bin_low_ns,bin_high_ns,pairs\n");
    static const char* names[kClasses] = {"kept_apart", "apart", "overlapping_unloaded",
                                          "carries_load"};
    for (int c = 0; c < kClasses; ++c)
      for (int b = 0; b < kBins; ++b)
        if (histogram[c][b] > 0)
          std::fprintf(f, "%s,%lld,%.2f,%.3f,%.3f,%.0f\n", names[c], count[c],
                       count[c] ? sum_ns[c] / count[c] : 0.0, std::pow(10.0, b / 80.0),
                       std::pow(10.0, (b + 1) / 80.0), histogram[c][b]);
    std::fclose(f);
  }
};

inline Probe& probe() {
  static Probe p;
  return p;
}

// Times one pair from its construction to its destruction (every exit of the loop's body).
struct PairTimer {
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  int outcome = kApart;
  double normal_force = 0.0;
  int slot_a = -1, slot_b = -1;
  double penalty = 0.0;
  ~PairTimer() {
    const double ns =
        std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
    probe().step.push_back({ns, normal_force, outcome, slot_a, slot_b, penalty});
  }
};

// Times the stage's per-tet work outside the pair loop.
struct SharedTimer {
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  ~SharedTimer() {
    probe().shared_ns +=
        std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
  }
};

}  // namespace fdem::pair_timing
