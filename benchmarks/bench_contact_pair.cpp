// Throughput of the per-pair potential-contact kernel: pair evaluations per second for
//   rejected     pairs whose boxes overlap but that a face plane separates,
//   overlapping  pairs with a real overlap (full exact integration), random depth,
//   shallow      overlapping pairs 0.5 % of a tet size past first touch (typical in a run),
//   mixed        every candidate pair of a random cloud (centres closer than one tet size, as a
//                cell-based broad phase would hand over),
//   face_on_face pairs of tets resting face on face (masonry), pressed 0.1 % of the size,
// each with the kernel and with the previous implementation (potential_contact_baseline), the
// per-pair cost distribution of both, plus the rejection test alone (with and without edge-edge
// axes) on the mixed set.  Then the overlapping, shallow and face-on-face pairs as lasting
// contacts: each pair evaluated again and again with its record of the evaluation before (its
// pieces' clips replayed, contact/clip_replay.hpp) against fresh clips of the same pairs, and
// replayed at the default contact.sliver_tolerance, as the contact stage runs them.
// Usage: bench_contact_pair [out.csv] [cpu_seconds_per_case]  (default bench_contact_pair.csv, 1 s)
// Rates are per second of thread CPU time.
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "contact/clip_replay.hpp"
#include "contact/contact_stage.hpp"
#include "contact/potential_contact_kernels.hpp"
#include "contact/tet_overlap.hpp"
#include "pair_timing.hpp"

using namespace fdem;

namespace {

TetCorners random_tet(std::mt19937_64& rng, double size, const Vec3& center) {
  const Vec3 regular[4] = {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  const Mat3 rot = q.toRotationMatrix();
  TetCorners t;
  for (int v = 0; v < 4; ++v)
    t.x[v] = center +
             rot * (regular[v] * size / std::sqrt(8.0) + 0.2 * size * Vec3(u(rng), u(rng), u(rng)));
  return t;
}

struct Pair {
  TetCorners a, b;
};

using bench::thread_cpu_seconds;

// Runs `body` over the pairs repeatedly for about `seconds` of this thread's CPU time (robust on
// a shared machine; also stops after 2 * seconds of wall time); returns evaluations per CPU
// second.
template <class Body>
double throughput(const std::vector<Pair>& pairs, double seconds, Body body, double& sink) {
  using clock = std::chrono::steady_clock;
  const auto wall_start = clock::now();
  const double cpu_start = thread_cpu_seconds();
  long long evaluations = 0;
  double cpu = 0.0, wall = 0.0;
  do {
    for (const Pair& p : pairs) sink += body(p);
    evaluations += static_cast<long long>(pairs.size());
    cpu = thread_cpu_seconds() - cpu_start;
    wall = std::chrono::duration<double>(clock::now() - wall_start).count();
  } while (cpu < seconds && wall < 2.0 * seconds);
  return static_cast<double>(evaluations) / cpu;
}

// Per-pair cost distribution: each pair timed alone (best of 3 batches of 8 evaluations, steady
// clock), kernel and baseline alternating pair by pair; percentiles in ns, also written to
// <csv>.distribution.csv.
void print_cost_distribution(
    const std::vector<std::pair<const char*, const std::vector<Pair>*>>& sets, double penalty,
    const std::string& csv_path) {
  std::ofstream csv(csv_path + ".distribution.csv");
  csv << "case,kernel,p10_ns,p50_ns,p90_ns,p99_ns,mean_ns\n";
  std::printf("per-pair cost (ns)                 p10      p50      p90      p99     mean\n");
  double sink = 0.0;
  for (const auto& [name, set] : sets) {
    std::vector<double> cost[2];
    for (const Pair& p : *set) {
      cost[0].push_back(bench::best_of_batches_ns(
          [&] { return potential_contact(p.a, p.b, penalty).energy; }, sink));
      cost[1].push_back(bench::best_of_batches_ns(
          [&] { return potential_contact_baseline(p.a, p.b, penalty).energy; }, sink));
    }
    for (int k = 0; k < 2; ++k) {
      std::vector<double>& c = cost[k];
      std::sort(c.begin(), c.end());
      double mean = 0.0;
      for (double x : c) mean += x / static_cast<double>(c.size());
      const auto at = [&](double q) { return c[static_cast<std::size_t>(q * (c.size() - 1))]; };
      const char* kernel = k == 0 ? "kernel" : "baseline";
      std::printf("%-18s %-9s %8.0f %8.0f %8.0f %8.0f %8.0f\n", name, kernel, at(0.1), at(0.5),
                  at(0.9), at(0.99), mean);
      csv << name << ',' << kernel << ',' << at(0.1) << ',' << at(0.5) << ',' << at(0.9) << ','
          << at(0.99) << ',' << mean << '\n';
    }
  }
  if (sink == 42.0) std::printf(" ");  // keep the evaluations
}

}  // namespace

int main(int argc, char** argv) {
  const std::string csv_path = argc > 1 ? argv[1] : "bench_contact_pair.csv";
  const double seconds = argc > 2 ? std::stod(argv[2]) : 1.0;
  const double penalty = 1.0e10;

  // A random cloud of unit tets; density such that a tet has a few candidate neighbours.
  std::mt19937_64 rng(12345);
  const int n_tets = 4000;
  const double box = 14.0;
  std::uniform_real_distribution<double> u(0.0, box);
  std::vector<TetCorners> cloud;
  std::vector<Vec3> centre;
  for (int i = 0; i < n_tets; ++i) {
    centre.emplace_back(u(rng), u(rng), u(rng));
    cloud.push_back(random_tet(rng, 1.0, centre.back()));
  }
  std::vector<Pair> mixed, rejected, overlapping;
  for (int i = 0; i < n_tets; ++i)
    for (int j = i + 1; j < n_tets; ++j) {
      if ((centre[i] - centre[j]).squaredNorm() > 1.0) continue;
      mixed.push_back({cloud[i], cloud[j]});
    }
  // Dedicated sets (boxes overlapping in both; same size distribution as the cloud).
  std::uniform_real_distribution<double> offset(-1.0, 1.0);
  while (rejected.size() < 20000 || overlapping.size() < 20000) {
    const TetCorners a = random_tet(rng, 1.0, Vec3::Zero());
    const TetCorners b = random_tet(rng, 1.0, Vec3(offset(rng), offset(rng), offset(rng)));
    if (!tet_boxes_intersect(a, b)) continue;
    const bool overlap = potential_contact(a, b, penalty).overlapping;
    if (overlap && overlapping.size() < 20000) overlapping.push_back({a, b});
    if (!overlap && !tets_may_overlap(a, b) && rejected.size() < 20000) rejected.push_back({a, b});
  }
  // Shallow contacts (0.5 % of the tet size past first touch along the centre line): what a
  // penalty-regulated simulation mostly sees.
  std::vector<Pair> shallow;
  for (const Pair& p : overlapping) {
    if (shallow.size() == 5000) break;
    const Vec3 dir = (tet_centroid(p.b) - tet_centroid(p.a)).normalized();
    auto moved = [&](double s) {
      Pair q = p;
      for (int v = 0; v < 4; ++v) q.b.x[v] += s * dir;
      return q;
    };
    double lo = 0.0, hi = 3.0;  // overlapping at lo, apart at hi
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      const Pair q = moved(mid);
      (potential_contact(q.a, q.b, penalty).overlapping ? lo : hi) = mid;
    }
    const Pair q = moved(hi - 0.005);
    if (potential_contact(q.a, q.b, penalty).overlapping) shallow.push_back(q);
  }
  // Face on face (masonry: blocks resting on each other): the bottom face of the upper tet lies
  // in the top face plane of the lower one, pressed 0.1 % of the size into it, with a random
  // in-plane shift and turn and random apexes (the meshes of the two blocks need not match).
  std::vector<Pair> face_on_face;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  while (face_on_face.size() < 5000) {
    const double depth = 1e-3, turn = 2.0 * M_PI * unit(rng);
    const Mat3 spin = Eigen::AngleAxisd(turn, Vec3::UnitZ()).toRotationMatrix();
    const Vec3 shift(0.6 * offset(rng), 0.6 * offset(rng), -depth);
    Pair p;
    p.a.x[0] = Vec3(0, 0, 0);
    p.a.x[1] = Vec3(1, 0, 0);
    p.a.x[2] = Vec3(0, 1, 0);
    p.a.x[3] = Vec3(0.3 + 0.4 * unit(rng), 0.3 + 0.4 * unit(rng), -0.5 - 0.5 * unit(rng));
    for (int v = 0; v < 3; ++v) p.b.x[v] = spin * p.a.x[v] + shift;
    p.b.x[3] =
        spin * Vec3(0.3 + 0.4 * unit(rng), 0.3 + 0.4 * unit(rng), 0.5 + 0.5 * unit(rng)) + shift;
    if (potential_contact(p.a, p.b, penalty).overlapping) face_on_face.push_back(p);
  }
  int mixed_overlapping = 0, mixed_face_pass = 0, mixed_edge_reject = 0;
  for (const Pair& p : mixed) {
    mixed_overlapping += potential_contact(p.a, p.b, penalty).overlapping;
    const bool may = tets_may_overlap(p.a, p.b);
    mixed_face_pass += may;
    mixed_edge_reject += may && separated_by_edge_axis(p.a, p.b);
  }

  double sink = 0.0;
  auto contact = [&](const Pair& p) { return potential_contact(p.a, p.b, penalty).energy; };
  auto baseline = [&](const Pair& p) {
    return potential_contact_baseline(p.a, p.b, penalty).energy;
  };
  auto contact_edge = [&](const Pair& p) {
    if (!tets_may_overlap(p.a, p.b) || separated_by_edge_axis(p.a, p.b)) return 0.0;
    return potential_contact(p.a, p.b, penalty).energy;
  };
  auto reject = [&](const Pair& p) { return tets_may_overlap(p.a, p.b) ? 1.0 : 0.0; };
  auto reject_edge = [&](const Pair& p) {
    return (tets_may_overlap(p.a, p.b) && !separated_by_edge_axis(p.a, p.b)) ? 1.0 : 0.0;
  };

  struct Row {
    std::string name;
    size_t pairs;
    double rate;
  };
  std::vector<Row> rows;
  // Each case with the kernel and with the previous implementation (baseline), interleaved so
  // that both see the same machine load.
  const std::pair<const char*, const std::vector<Pair>*> cases[] = {
      {"rejected_pairs", &rejected},
      {"overlapping_pairs", &overlapping},
      {"shallow_overlapping_pairs", &shallow},
      {"face_on_face_pairs", &face_on_face},
      {"mixed_cloud", &mixed}};
  for (const auto& [name, set] : cases) {
    rows.push_back({name, set->size(), throughput(*set, seconds, contact, sink)});
    rows.push_back(
        {std::string(name) + "_baseline", set->size(), throughput(*set, seconds, baseline, sink)});
  }
  rows.push_back(
      {"mixed_cloud_with_edge_axes", mixed.size(), throughput(mixed, seconds, contact_edge, sink)});
  rows.push_back({"rejection_only_mixed", mixed.size(), throughput(mixed, seconds, reject, sink)});
  rows.push_back({"rejection_with_edge_axes_mixed", mixed.size(),
                  throughput(mixed, seconds, reject_edge, sink)});

  // Lasting contacts: the same pairs evaluated repeatedly, each with its own record of the
  // evaluation before (every piece replays: the positions do not change), against fresh clips.
  for (const auto& [name, set] :
       {std::pair<const char*, const std::vector<Pair>*>{"overlapping_pairs", &overlapping},
        {"shallow_overlapping_pairs", &shallow},
        {"face_on_face_pairs", &face_on_face}}) {
    std::vector<PairClipRecords> records(set->size());
    auto lasting = [&](const Pair& p, bool replay, double tolerance = 0.0) {
      const std::size_t i = static_cast<std::size_t>(&p - set->data());
      PreparedContactor prepared;
      prepare_contactor(p.a, prepared);
      TetGeometry geometry;
      compute_tet_geometry(p.b, geometry, false);
      if (!replay) return potential_contact(prepared, geometry, penalty).energy;
      ClipMemo memo = records[i].next();
      return potential_contact(prepared, geometry, penalty, tolerance, &memo).energy;
    };
    rows.push_back({std::string(name) + "_lasting_replayed", set->size(),
                    throughput(
                        *set, seconds, [&](const Pair& p) { return lasting(p, true); }, sink)});
    rows.push_back({std::string(name) + "_lasting_fresh", set->size(),
                    throughput(
                        *set, seconds, [&](const Pair& p) { return lasting(p, false); }, sink)});
    // As the contact stage runs them: replayed, and with the default contact.sliver_tolerance
    // (pieces proven below 1/1000 of a face pressed as deep left out, with their flux).
    for (PairClipRecords& r : records) r = PairClipRecords();
    const double tolerance = ContactSettings{}.sliver_tolerance;
    rows.push_back(
        {std::string(name) + "_lasting_replayed_default_tolerance", set->size(),
         throughput(
             *set, seconds, [&](const Pair& p) { return lasting(p, true, tolerance); }, sink)});
  }

  std::printf("bench_contact_pair: potential contact kernel, penalty %.1e Pa\n", penalty);
  std::printf(
      "mixed cloud: %zu candidate pairs, %d overlapping, %d pass boxes+face planes, "
      "%d of those separated by an edge axis\n",
      mixed.size(), mixed_overlapping, mixed_face_pass, mixed_edge_reject);
  std::printf("%-32s %10s %16s %12s\n", "case", "pairs", "pairs/s", "ns/pair");
  std::ofstream csv(csv_path);
  csv << "case,pairs,pairs_per_second,ns_per_pair\n";
  for (const Row& r : rows) {
    std::printf("%-32s %10zu %16.4e %12.1f\n", r.name.c_str(), r.pairs, r.rate, 1e9 / r.rate);
    csv << r.name << ',' << r.pairs << ',' << r.rate << ',' << 1e9 / r.rate << '\n';
  }
  std::printf("speed-up over the baseline (same run):");
  for (std::size_t r = 0; r + 1 < rows.size(); ++r)
    if (rows[r + 1].name == rows[r].name + "_baseline")
      std::printf(" %s %.2fx", rows[r].name.c_str(), rows[r].rate / rows[r + 1].rate);
  std::printf("\nreplayed against fresh clips (same run):");
  for (std::size_t r = 0; r + 1 < rows.size(); ++r)
    if (rows[r].name.size() > 9 && rows[r].name.substr(rows[r].name.size() - 9) == "_replayed")
      std::printf(" %s %.2fx", rows[r].name.c_str(), rows[r].rate / rows[r + 1].rate);
  std::printf("\n");
  print_cost_distribution(
      {{"overlapping_pairs", &overlapping}, {"shallow", &shallow}, {"face_on_face", &face_on_face}},
      penalty, csv_path);
  std::printf("(checksum %.6e) wrote %s\n", sink, csv_path.c_str());
  return 0;
}
