// Contact detection (broad phase) cost per element: Munjiza NBS vs sort-and-sweep vs brute force,
// for N = 1e3 .. 1e5 (1e6 with a second argument), at several packing densities and domain
// shapes.  Prints a table and writes CSV.
//
//   bench_contact_detection [csv_path = bench_contact_detection.csv] [max_n = 100000]
//
// Scenes (tet size h = 1 m, buffer = 0.05 m):
//   mesh      a tet mesh of a cube lattice (6 tets per unit cube sharing nodes): an intact solid,
//             where every tet's box is its cube, so neighbours overlap heavily;
//   dense     one random tet per site of a cubic lattice with spacing 1 m;
//   sparse10  the same tets on a lattice with spacing 10^(1/3) m: 10x lower packing density,
//             10x the domain volume;
//   column    dense tets in a 10 x 10 x N/100 column (domain aspect ratio N/1000 : 1).
// Times are the best of up to 20 repetitions, in thread CPU time.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "contact/broad_phase.hpp"
#include "contact/nbs.hpp"

using namespace fdem;

namespace {

struct Scene {
  std::string name;
  LocalIndex n = 0;
  std::vector<double> lo, hi;
  double domain_volume = 0.0;  // m^3, of the lattice
};

void add_tet_box(Scene& s, const double (*v)[3]) {
  for (int k = 0; k < 3; ++k) {
    double mn = v[0][k], mx = v[0][k];
    for (int i = 1; i < 4; ++i) {
      mn = std::min(mn, v[i][k]);
      mx = std::max(mx, v[i][k]);
    }
    s.lo.push_back(mn);
    s.hi.push_back(mx);
  }
  ++s.n;
}

// Lattice dimensions holding at least `sites` sites, cube-like or as a 10 x 10 column.
void lattice_dims(LocalIndex sites, bool column, int dims[3]) {
  if (column) {
    dims[0] = dims[1] = 10;
    dims[2] = static_cast<int>((sites + 99) / 100);
    return;
  }
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(sites)) - 1e-9));
  dims[0] = dims[1] = side;
  dims[2] = static_cast<int>((sites + side * side - 1) / (side * side));
}

Scene random_tet_lattice(const std::string& name, LocalIndex n, double spacing, bool column,
                         std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-0.5, 0.5);
  Scene s;
  s.name = name;
  int dims[3];
  lattice_dims(n, column, dims);
  s.domain_volume = dims[0] * dims[1] * dims[2] * spacing * spacing * spacing;
  for (int z = 0; z < dims[2] && s.n < n; ++z)
    for (int y = 0; y < dims[1] && s.n < n; ++y)
      for (int x = 0; x < dims[0] && s.n < n; ++x) {
        double v[4][3];
        const double site[3] = {x * spacing, y * spacing, z * spacing};
        for (auto& node : v)
          for (int k = 0; k < 3; ++k) node[k] = site[k] + 1.5 * unit(rng);  // nodes within 1.5 m
        add_tet_box(s, v);
      }
  return s;
}

// Kuhn subdivision of each unit cube into 6 tets along the main diagonal; the shared lattice
// nodes are jittered by up to +-0.1 m (a distorted but valid mesh).
Scene tet_mesh(LocalIndex n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> jitter(-0.1, 0.1);
  Scene s;
  s.name = "mesh";
  int dims[3];
  lattice_dims((n + 5) / 6, false, dims);
  s.domain_volume = static_cast<double>(dims[0]) * dims[1] * dims[2];
  const int nx = dims[0] + 1, ny = dims[1] + 1, nz = dims[2] + 1;
  std::vector<double> nodes(3 * static_cast<std::size_t>(nx) * ny * nz);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        double* p = &nodes[3 * ((static_cast<std::size_t>(z) * ny + y) * nx + x)];
        p[0] = x + jitter(rng);
        p[1] = y + jitter(rng);
        p[2] = z + jitter(rng);
      }
  static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int z = 0; z < dims[2] && s.n < n; ++z)
    for (int y = 0; y < dims[1] && s.n < n; ++y)
      for (int x = 0; x < dims[0] && s.n < n; ++x)
        for (int t = 0; t < 6 && s.n < n; ++t) {
          double v[4][3];
          int p[3] = {x, y, z};
          for (int corner = 0; corner < 4; ++corner) {
            if (corner > 0) p[perms[t][corner - 1]] += 1;
            const double* q =
                &nodes[3 * ((static_cast<std::size_t>(p[2]) * ny + p[1]) * nx + p[0])];
            for (int k = 0; k < 3; ++k) v[corner][k] = q[k];
          }
          add_tet_box(s, v);
        }
  return s;
}

// CPU time of this thread (s): unlike wall time it does not count the time the benchmark is
// preempted on a shared machine (cache and memory-bandwidth contention still show).
double thread_cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Row {
  std::string scene, algorithm;
  LocalIndex n;
  double domain_volume, pairs_per_element, ns_per_element, bytes_per_element, tests_per_element;
  int reps;
};

}  // namespace

int main(int argc, char** argv) {
  const std::string csv_path = argc > 1 ? argv[1] : "bench_contact_detection.csv";
  const long max_n = argc > 2 ? std::atol(argv[2]) : 100000;
  const double buffer = 0.05;  // m
  std::mt19937_64 rng(2024);
  std::vector<Row> rows;

  std::printf("%-9s %-11s %8s %11s %10s %10s %10s %10s\n", "scene", "algorithm", "N", "volume_m3",
              "pairs/el", "ns/el", "bytes/el", "tests/el");
  const char* scene_names[] = {"mesh", "dense", "sparse10", "column"};
  auto make_scene = [&](int which, LocalIndex n) {
    switch (which) {
      case 0:
        return tet_mesh(n, rng);
      case 1:
        return random_tet_lattice("dense", n, 1.0, false, rng);
      case 2:
        return random_tet_lattice("sparse10", n, std::cbrt(10.0), false, rng);
      default:
        return random_tet_lattice("column", n, 1.0, true, rng);
    }
  };
  for (long n_long = 1000; n_long <= max_n; n_long *= 10) {
    const LocalIndex n = static_cast<LocalIndex>(n_long);
    for (int which = 0; which < 4; ++which) {
      // Each repetition times a freshly generated scene (so small cases cannot profit from a
      // branch predictor trained on the previous repetition); the best time is kept.  NBS runs
      // 20 repetitions; the others stop once they have used a 1 s budget.  Every list is
      // compared with the NBS list of the same repetition.
      const bool with_brute = n_long <= 10000;
      const int n_algorithms = with_brute ? 3 : 2;
      const char* algorithm_names[] = {"nbs", "sort_sweep", "brute_force"};
      double best[3] = {1e300, 1e300, 1e300}, spent[3] = {0, 0, 0};
      int reps[3] = {0, 0, 0};
      NbsDetector nbs;
      SortSweepDetector sweep;
      std::vector<CandidatePair> pairs[3];
      Scene s;
      double bytes[3] = {0, 0, 0}, tests[3] = {0, 0, 0};
      for (int rep = 0; rep < 20; ++rep) {
        s = make_scene(which, n);
        for (int a = 0; a < n_algorithms; ++a) {
          if (a > 0 && rep > 0 && spent[a] > 1.0) continue;  // NBS runs every repetition
          const double t0 = thread_cpu_seconds();
          if (a == 0) nbs.detect(s.lo.data(), s.hi.data(), s.n, buffer, pairs[0]);
          if (a == 1) sweep.detect(s.lo.data(), s.hi.data(), s.n, buffer, pairs[1]);
          if (a == 2) detect_brute_force(s.lo.data(), s.hi.data(), s.n, buffer, pairs[2]);
          const double t = thread_cpu_seconds() - t0;
          best[a] = std::min(best[a], t);
          spent[a] += t;
          ++reps[a];
          if (a == 0) {
            bytes[0] = double(nbs.stats().workspace_bytes) / s.n;
            tests[0] = double(nbs.stats().box_tests) / s.n;
          } else if (a == 1) {
            bytes[1] = double(sweep.workspace_bytes()) / s.n;
            tests[1] = double(sweep.box_tests()) / s.n;
          } else {
            bytes[2] = 48.0;  // the inflated boxes
            tests[2] = 0.5 * (s.n - 1.0);
          }
          if (a > 0 && pairs[a] != pairs[0]) {
            std::fprintf(stderr, "MISMATCH: %s and NBS pair lists differ (%s, N=%d)\n",
                         algorithm_names[a], s.name.c_str(), s.n);
            return 1;
          }
        }
      }
      for (int a = 0; a < n_algorithms; ++a) {
        rows.push_back({scene_names[which], algorithm_names[a], s.n, s.domain_volume,
                        double(pairs[0].size()) / s.n, 1e9 * best[a] / s.n, bytes[a], tests[a],
                        reps[a]});
        const Row& r = rows.back();
        std::printf("%-9s %-11s %8d %11.4g %10.2f %10.1f %10.1f %10.1f\n", r.scene.c_str(),
                    r.algorithm.c_str(), r.n, r.domain_volume, r.pairs_per_element,
                    r.ns_per_element, r.bytes_per_element, r.tests_per_element);
      }
      std::fflush(stdout);
    }
  }

  std::ofstream csv(csv_path);
  csv << "scene,algorithm,n,domain_volume_m3,pairs_per_element,ns_per_element,bytes_per_element,"
         "box_tests_per_element,repetitions\n";
  for (const Row& r : rows) {
    csv << r.scene << ',' << r.algorithm << ',' << r.n << ',' << r.domain_volume << ','
        << r.pairs_per_element << ',' << r.ns_per_element << ',' << r.bytes_per_element << ','
        << r.tests_per_element << ',' << r.reps << '\n';
  }
  std::printf("wrote %s\n", csv_path.c_str());
  return 0;
}
