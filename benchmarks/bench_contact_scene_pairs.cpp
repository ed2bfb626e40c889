// What one contact pair costs in a real scene, as the contact stage evaluates it, against the
// kernel of issue 12's start: the per-pair cost distribution of every candidate pair of one step.
//
//   bench_contact_scene_pairs SCENE.yaml TIME [out.csv] [--label NAME] [--set key=value ...]
//       [--turns SECONDS] [--count PASSES]
//
// The scene runs (one rank, no output) to just before TIME.  The candidate pairs of the last
// step and the positions before it (x0) and after it (x1) are kept; then each pair at x1 is timed
// alone (best of 3 batches of 8 evaluations, steady clock), in two ways:
//   baseline  potential_contact_baseline on the pair's corners: the kernel of issue 12's start,
//             no sliver skip, every clip afresh (it includes its own box test);
//   stage     what the contact stage does for the pair: the tets' boxes, then potential_contact
//             on the prepared contactor and the target's geometry, with the scene's sliver
//             tolerance, the clip record and apart memo of the pair's evaluation at x0, and the
//             clips met before (one store for all pairs, as the stage keeps one per rank).
// The per-tet work the stage shares between a tet's pairs (geometry, box, prepared contactor) is
// timed once for all tets and reported per pair.  Pairs the stage would not evaluate at all
// (kept apart by their gap) are timed like the others: the figures are an upper bound for it.
// Classes: every candidate pair, the pairs the baseline finds overlapping, and of those the ones
// the stage integrates (not skipped under the tolerance: the pairs that carry load).  The stage's
// results are checked against the exact kernel (tolerance 0, fresh clips): the largest nodal
// force difference relative to the step's largest pair force.
// With --turns, the integrated pairs are then evaluated in turn, one after the other as the stage
// meets them, again and again, the baseline and the stage alternating in three rounds for SECONDS
// of CPU time in all: their mean cost without a hot loop on one pair (least of the rounds; CSV
// class integrated_in_turn, percentiles empty), and a steady loop to profile.
// With --count PASSES, nothing is timed: the integrated pairs are evaluated in turn PASSES times
// by the stage's path inside count_in_turn, for counting its instructions under callgrind
// (valgrind --tool=callgrind --toggle-collect='*count_in_turn*'): a figure that does not move
// with the machine's load, for comparing two builds of the kernel.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "contact/clip_replay.hpp"
#include "contact/contact_stage.hpp"
#include "contact/potential_contact_kernels.hpp"
#include "contact/tet_overlap.hpp"
#include "drivers/simulation.hpp"
#include "io/scene_reader.hpp"
#include "pair_timing.hpp"

using namespace fdem;

namespace {

// Every tet's corners at the model's current positions.
std::vector<TetCorners> corners_of(const Model& model) {
  std::vector<TetCorners> out(model.tets.size());
  for (LocalIndex t = 0; t < model.tets.size(); ++t) out[t] = tet_corners(model, t);
  return out;
}

struct Stats {
  double p10 = 0, p50 = 0, p90 = 0, p99 = 0, mean = 0, sum = 0;
};

Stats stats_of(std::vector<double> v) {
  Stats s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  for (double x : v) s.sum += x;
  s.mean = s.sum / static_cast<double>(v.size());
  const auto at = [&](double q) { return v[static_cast<std::size_t>(q * (v.size() - 1))]; };
  s.p10 = at(0.1), s.p50 = at(0.5), s.p90 = at(0.9), s.p99 = at(0.99);
  return s;
}

// `evaluate(i)` for every pair in `pairs`, `passes` times (not inlined: callgrind's toggle).
template <class Evaluate>
__attribute__((noinline)) double count_in_turn(const std::vector<std::size_t>& pairs, int passes,
                                               Evaluate&& evaluate) {
  double sink = 0.0;
  for (int pass = 0; pass < passes; ++pass)
    for (std::size_t i : pairs) sink += evaluate(i);
  return sink;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: bench_contact_scene_pairs SCENE.yaml TIME [out.csv] [--label NAME] "
                 "[--set key=value ...]\n");
    return 2;
  }
  const std::string scene_path = argv[1];
  const double until = std::stod(argv[2]);
  std::string csv_path = "bench_contact_scene_pairs.csv", label = scene_path;
  std::vector<std::string> overrides;
  double turns_seconds = 0.0;
  int count_passes = 0;
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--set" && i + 1 < argc)
      overrides.push_back(argv[++i]);
    else if (a == "--label" && i + 1 < argc)
      label = argv[++i];
    else if (a == "--turns" && i + 1 < argc)
      turns_seconds = std::stod(argv[++i]);
    else if (a == "--count" && i + 1 < argc)
      count_passes = std::stoi(argv[++i]);
    else
      csv_path = a;
  }
  const Scene scene = read_scene(scene_path, overrides);
  RunOptions options;
  options.quiet = true;
  options.write_output = false;
  auto sim = make_simulation(scene, options);
  while (sim->time() + 2.0 * sim->time_step() < until) sim->step();
  const std::vector<TetCorners> x0 = corners_of(sim->model());
  sim->step();
  const std::vector<TetCorners> x1 = corners_of(sim->model());
  const std::vector<CandidatePair> pairs = sim->contact_stage()->candidates();
  const double tolerance = scene.contact_sliver_tolerance;
  const double penalty = 1.0e10;  // the cost does not depend on it; the scene's is per material
  const std::size_t n = pairs.size();

  // The stage's per-tet work at x0 and x1: geometry (with face normals) and box of every tet in a
  // pair, the prepared contactor of every first tet.
  std::vector<TetGeometry> geometry0(x0.size()), geometry1(x1.size());
  std::vector<TetBox> box1(x1.size());
  std::vector<PreparedContactor> prepared0(x0.size()), prepared1(x1.size());
  std::vector<char> in_pair(x1.size(), 0), contactor(x1.size(), 0);
  for (const CandidatePair& p : pairs) in_pair[p.a] = in_pair[p.b] = 1, contactor[p.a] = 1;
  for (std::size_t t = 0; t < x0.size(); ++t) {
    if (!in_pair[t]) continue;
    compute_tet_geometry(x0[t], geometry0[t]);
    if (contactor[t]) prepare_contactor(geometry0[t], prepared0[t]);
  }
  double sink = 0.0;
  const double per_tet_ns = bench::best_of_batches_ns(
      [&] {
        for (std::size_t t = 0; t < x1.size(); ++t) {
          if (!in_pair[t]) continue;
          box1[t] = tet_box(x1[t]);
          compute_tet_geometry(x1[t], geometry1[t]);
          if (contactor[t]) prepare_contactor(geometry1[t], prepared1[t]);
        }
        return geometry1[pairs.empty() ? 0 : pairs[0].a].edge_det;
      },
      sink);

  // The evaluation at x0 leaves each pair its clip record and apart memo, as in the stage, and
  // every clip it made in the clips met before, which the stage's path then walks where a pair's
  // record no longer fits (as the stage's own, shared by all pairs of a rank).
  piece_clip::ClipTopologies topologies;
  std::vector<PairClipRecords> records(n);
  std::vector<std::vector<std::uint8_t>> record0(n);
  std::vector<std::uint8_t> apart0(n, ClipMemo::kNotApart);
  for (std::size_t i = 0; i < n; ++i) {
    ClipMemo memo = records[i].next();
    memo.topologies = &topologies;
    potential_contact(prepared0[pairs[i].a], geometry0[pairs[i].b], penalty, tolerance, &memo);
    record0[i].assign(memo.record->data(), memo.record->data() + memo.record->size());
    apart0[i] = memo.apart_now;
  }
  RecordBytes scratch;
  const auto stage_pair = [&](std::size_t i) {
    const CandidatePair& p = pairs[i];
    if (!boxes_intersect(box1[p.a], box1[p.b])) return ContactPairResult{};
    ClipMemo memo;
    memo.previous = record0[i].empty() ? nullptr : record0[i].data();
    memo.previous_end = record0[i].data() + record0[i].size();
    scratch.clear();
    memo.record = &scratch;
    memo.apart_before = apart0[i];
    memo.topologies = &topologies;
    return potential_contact(prepared1[p.a], geometry1[p.b], penalty, tolerance, &memo);
  };

  std::vector<double> cost[3][2];  // [all, overlapping, integrated][baseline, stage]
  std::vector<std::size_t> integrated;
  std::size_t boxes_meet = 0, overlapping = 0, stage_overlapping = 0;
  double largest_pair_force = 0.0, worst_difference = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const CandidatePair& p = pairs[i];
    const ContactPairResult base = potential_contact_baseline(x1[p.a], x1[p.b], penalty);
    const ContactPairResult now = stage_pair(i);
    const ContactPairResult exact =
        potential_contact(prepared1[p.a], geometry1[p.b], penalty, 0.0, nullptr);
    boxes_meet += boxes_intersect(box1[p.a], box1[p.b]);
    overlapping += base.overlapping;
    stage_overlapping += now.overlapping;
    largest_pair_force = std::max(largest_pair_force, largest_nodal_force(exact));
    worst_difference = std::max(worst_difference, largest_nodal_force_difference(now, exact));
    if (count_passes > 0) {  // nothing timed
      if (base.overlapping && now.overlapping) integrated.push_back(i);
      continue;
    }
    const double b = bench::best_of_batches_ns(
        [&] { return potential_contact_baseline(x1[p.a], x1[p.b], penalty).energy; }, sink);
    const double s = bench::best_of_batches_ns([&] { return stage_pair(i).energy; }, sink);
    cost[0][0].push_back(b);
    cost[0][1].push_back(s);
    if (base.overlapping) {
      cost[1][0].push_back(b);
      cost[1][1].push_back(s);
    }
    if (base.overlapping && now.overlapping) {
      integrated.push_back(i);
      cost[2][0].push_back(b);
      cost[2][1].push_back(s);
    }
  }
  if (count_passes > 0) {
    sink += count_in_turn(integrated, count_passes,
                          [&](std::size_t i) { return stage_pair(i).energy; });
    std::printf(
        "bench_contact_scene_pairs: %s at t = %.6g s: %zu integrated pairs evaluated in "
        "turn %d times (count_in_turn)%s\n",
        label.c_str(), sim->time(), integrated.size(), count_passes, sink == 42.0 ? " " : "");
    return 0;
  }
  const double per_tet_per_pair = n > 0 ? per_tet_ns / static_cast<double>(n) : 0.0;

  std::printf("bench_contact_scene_pairs: %s at t = %.6g s (%s), sliver tolerance %g\n",
              label.c_str(), sim->time(), scene_path.c_str(), tolerance);
  std::printf(
      "%zu candidate pairs, boxes meet %zu, overlapping %zu (the stage integrates %zu, skips the "
      "rest under the tolerance)\n",
      n, boxes_meet, overlapping, stage_overlapping);
  std::printf(
      "stage's per-tet work (geometry, box, prepared contactor): %.0f ns per pair; largest force "
      "difference stage vs exact: %.2e of the step's largest pair force\n",
      per_tet_per_pair, largest_pair_force > 0 ? worst_difference / largest_pair_force : 0.0);
  std::printf("%-12s %-9s %8s %8s %8s %8s %8s %10s\n", "pairs", "path", "p10", "p50", "p90", "p99",
              "mean", "mean ratio");
  std::ofstream csv(csv_path, std::ios::app);
  if (csv.tellp() == 0)
    csv << "scene,time,sliver_tolerance,class,pairs,path,p10_ns,p50_ns,p90_ns,p99_ns,mean_ns,"
           "per_tet_ns_per_pair,mean_ratio_with_per_tet\n";
  for (int k = 0; k < 3; ++k) {
    const Stats base = stats_of(cost[k][0]), stage = stats_of(cost[k][1]);
    const double ratio = base.mean / (stage.mean + per_tet_per_pair);
    const char* cls = k == 0 ? "all" : k == 1 ? "overlapping" : "integrated";
    for (int path = 0; path < 2; ++path) {
      const Stats& s = path == 0 ? base : stage;
      std::printf("%-12s %-9s %8.0f %8.0f %8.0f %8.0f %8.0f", cls, path == 0 ? "baseline" : "stage",
                  s.p10, s.p50, s.p90, s.p99, s.mean);
      if (path == 1) std::printf(" %9.2fx (per-tet work added to the stage's mean)", ratio);
      std::printf("\n");
      csv << label << ',' << sim->time() << ',' << tolerance << ',' << cls << ','
          << cost[k][path].size() << ',' << (path == 0 ? "baseline" : "stage") << ',' << s.p10
          << ',' << s.p50 << ',' << s.p90 << ',' << s.p99 << ',' << s.mean << ','
          << (path == 1 ? per_tet_per_pair : 0.0) << ',' << (path == 1 ? ratio : 1.0) << '\n';
    }
  }
  if (turns_seconds > 0.0 && !integrated.empty()) {
    // ns per evaluation of `evaluate(i)` over the integrated pairs in turn for `seconds` (CPU).
    const auto in_turn = [&](auto evaluate, double seconds) {
      long long evaluations = 0;
      const double start = bench::thread_cpu_seconds();
      double elapsed = 0.0;
      while ((elapsed = bench::thread_cpu_seconds() - start) < seconds) {
        for (std::size_t i : integrated) sink += evaluate(i);
        evaluations += static_cast<long long>(integrated.size());
      }
      return 1e9 * elapsed / static_cast<double>(evaluations);
    };
    // Three rounds, the two paths alternating; the least of each (a busy moment only slows).
    double stage_ns = 1e30, base_ns = 1e30;
    for (int round = 0; round < 3; ++round) {
      stage_ns = std::min(stage_ns, in_turn([&](std::size_t i) { return stage_pair(i).energy; },
                                            turns_seconds / 6.0));
      base_ns = std::min(
          base_ns,
          in_turn(
              [&](std::size_t i) {
                return potential_contact_baseline(x1[pairs[i].a], x1[pairs[i].b], penalty).energy;
              },
              turns_seconds / 6.0));
    }
    const double ratio = base_ns / (stage_ns + per_tet_per_pair);
    std::printf(
        "integrated pairs in turn: baseline %.0f ns, stage %.0f ns (+%.0f per-tet), %.2fx\n",
        base_ns, stage_ns, per_tet_per_pair, ratio);
    for (int path = 0; path < 2; ++path)
      csv << label << ',' << sim->time() << ',' << tolerance << ",integrated_in_turn,"
          << integrated.size() << ',' << (path == 0 ? "baseline" : "stage") << ",,,,,"
          << (path == 0 ? base_ns : stage_ns) << ',' << (path == 1 ? per_tet_per_pair : 0.0) << ','
          << (path == 1 ? ratio : 1.0) << '\n';
  }
  if (sink == 42.0) std::printf(" ");
  std::printf("appended to %s\n", csv_path.c_str());
  return 0;
}
