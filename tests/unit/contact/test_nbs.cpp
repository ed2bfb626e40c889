// NBS, sort-and-sweep and brute force must return the identical sorted pair list.
#include <algorithm>
#include <catch2/catch.hpp>
#include <limits>
#include <random>
#include <vector>

#include "contact/broad_phase.hpp"
#include "contact/nbs.hpp"
#include "core/error.hpp"
#include "test_nbs_helpers.hpp"

using namespace fdem;
using fdem::test::random_tets;
using fdem::test::side_for;

namespace {

struct ThreeWay {
  std::vector<CandidatePair> brute, nbs, sweep;
};

// Runs the three algorithms (NBS and sweep with the given reusable detectors) and checks that
// they agree exactly and that the list is sorted with a < b.
ThreeWay run_all(NbsDetector& nbs, SortSweepDetector& sweep, const std::vector<double>& lo,
                 const std::vector<double>& hi, LocalIndex n, double buffer, PairFilter keep = {}) {
  ThreeWay r;
  detect_brute_force(lo.data(), hi.data(), n, buffer, r.brute, keep);
  nbs.detect(lo.data(), hi.data(), n, buffer, r.nbs, keep);
  sweep.detect(lo.data(), hi.data(), n, buffer, r.sweep, keep);
  CHECK(std::is_sorted(r.brute.begin(), r.brute.end()));
  CHECK(std::adjacent_find(r.brute.begin(), r.brute.end()) == r.brute.end());
  for (const CandidatePair& p : r.brute) REQUIRE(p.a < p.b);
  REQUIRE(r.nbs.size() == r.brute.size());
  REQUIRE(r.sweep.size() == r.brute.size());
  CHECK(r.nbs == r.brute);
  CHECK(r.sweep == r.brute);
  return r;
}

}  // namespace

TEST_CASE("NBS, sort-sweep and brute force agree on random tet clouds", "[contact][nbs]") {
  struct Config {
    const char* name;
    double fraction;               // box volume fraction (packing density)
    double h_min, h_max;           // tet size range (m)
    std::array<double, 3> aspect;  // domain shape (scaled to the volume)
    std::array<double, 3> origin;
  };
  const Config configs[] = {
      {"dense cube", 2.0, 1.0, 1.0, {1, 1, 1}, {0, 0, 0}},
      {"sparse cube", 0.02, 1.0, 1.0, {1, 1, 1}, {-50, -50, -50}},
      {"mixed sizes 100x", 0.3, 0.05, 5.0, {1, 1, 1}, {-3, 7, -11}},
      {"long bar (100:1:1)", 0.4, 1.0, 1.5, {100, 1, 1}, {-1e3, -2, 5}},
      {"thin plate (1:1:0.01)", 0.3, 0.2, 0.4, {1, 1, 0.01}, {-7, -7, -1e-3}},
      {"mixed sizes, far from origin", 0.2, 0.01, 1.0, {1, 3, 1}, {-1e5, 2e5, -3e5}},
  };
  const LocalIndex sizes[] = {0, 1, 2, 3, 17, 200, 3000};
  NbsDetector nbs;  // reused across all calls: workspace reuse must not leak state
  SortSweepDetector sweep;
  std::mt19937_64 rng(12345);
  std::size_t total_pairs = 0;
  for (const Config& c : configs) {
    for (LocalIndex n : sizes) {
      const double h_mean = std::sqrt(c.h_min * c.h_max);
      const double side = side_for(n, h_mean, c.fraction);
      const double scale = side / std::cbrt(c.aspect[0] * c.aspect[1] * c.aspect[2]);
      std::array<double, 3> size{scale * c.aspect[0], scale * c.aspect[1], scale * c.aspect[2]};
      auto cloud = random_tets(n, c.origin, size, c.h_min, c.h_max, rng);
      for (double buffer : {0.0, 0.1 * h_mean}) {
        INFO(c.name << ", n = " << n << ", buffer = " << buffer);
        ThreeWay r = run_all(nbs, sweep, cloud.lo, cloud.hi, n, buffer);
        total_pairs += r.brute.size();
        if (n <= 1) CHECK(r.brute.empty());
        // Mixed sizes must exercise the coarser NBS level.
        if (c.h_max / c.h_min >= 100 && n >= 200) CHECK(nbs.stats().large_elements > 0);
        // Linear work: a bounded number of box tests per element and per pair found.
        if (n >= 200) CHECK(nbs.stats().box_tests < 20 * (n + r.brute.size()));
      }
    }
  }
  CHECK(total_pairs > 20000);  // the comparison saw many real pairs
}

TEST_CASE("NBS and sort-sweep agree with brute force after random motion", "[contact][nbs]") {
  std::mt19937_64 rng(777);
  const LocalIndex n = 1500;
  const double side = side_for(n, 1.0, 0.3);
  auto cloud = random_tets(n, {-side / 2, -side / 2, -side / 2}, {side, side, side}, 0.3, 3.0, rng);
  NbsDetector nbs;
  SortSweepDetector sweep;
  std::normal_distribution<double> jump(0.0, 0.5);
  std::size_t changed = 0;
  std::vector<CandidatePair> previous;
  for (int step = 0; step < 8; ++step) {
    INFO("step " << step);
    ThreeWay r = run_all(nbs, sweep, cloud.lo, cloud.hi, n, 0.05);
    if (step > 0 && r.brute != previous) ++changed;
    previous = r.brute;
    // Rigid random translation of each tet plus a small distortion of its nodes.
    for (LocalIndex e = 0; e < n; ++e) {
      const double t[3] = {jump(rng), jump(rng), jump(rng)};
      for (int v = 0; v < 4; ++v)
        for (int k = 0; k < 3; ++k) cloud.x[12 * e + 3 * v + k] += t[k] + 0.05 * jump(rng);
    }
    cloud.update_boxes();
  }
  CHECK(changed == 7);  // the motion really changed the pair lists

  // A smaller and then larger N with the same detectors (workspace shrinks/grows).
  for (LocalIndex m : {LocalIndex(10), LocalIndex(0), LocalIndex(2500)}) {
    auto other = random_tets(m, {0, 0, 0}, {20, 20, 20}, 0.5, 2.0, rng);
    INFO("n = " << m);
    run_all(nbs, sweep, other.lo, other.hi, m, 0.0);
  }
}

TEST_CASE("filter is applied identically by every algorithm", "[contact][nbs]") {
  std::mt19937_64 rng(99);
  const LocalIndex n = 2000;
  auto cloud = random_tets(n, {0, 0, 0}, {15, 15, 15}, 0.5, 1.5, rng);
  // Elements 10k..10k+9 form one body: pairs inside a body are skipped.
  auto different_body = [](LocalIndex a, LocalIndex b) { return a / 10 != b / 10; };
  NbsDetector nbs;
  SortSweepDetector sweep;
  ThreeWay filtered = run_all(nbs, sweep, cloud.lo, cloud.hi, n, 0.1, different_body);
  std::vector<CandidatePair> all;
  detect_brute_force(cloud.lo.data(), cloud.hi.data(), n, 0.1, all);
  std::vector<CandidatePair> expected;
  for (const CandidatePair& p : all)
    if (p.a / 10 != p.b / 10) expected.push_back(p);
  CHECK(filtered.brute == expected);
  CHECK(expected.size() < all.size());
  CHECK(expected.size() > 1000);
}

TEST_CASE("NBS edge case: all elements in one cell", "[contact][nbs]") {
  const LocalIndex n = 60;
  std::vector<double> lo(3 * n), hi(3 * n);
  for (LocalIndex i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      lo[3 * i + k] = -2.0 + 1e-3 * i;  // nearly identical boxes
      hi[3 * i + k] = -1.0 + 1e-3 * i;
    }
  }
  NbsDetector nbs;
  SortSweepDetector sweep;
  ThreeWay r = run_all(nbs, sweep, lo, hi, n, 0.0);
  CHECK(r.nbs.size() == static_cast<std::size_t>(n * (n - 1) / 2));
  REQUIRE(nbs.stats().levels.size() == 1);
  CHECK(nbs.stats().levels[0].occupied_cells == 1);
}

TEST_CASE("NBS edge case: touching boxes exactly on cell boundaries", "[contact][nbs]") {
  // A k^3 lattice of boxes of side 0.5 (m) with min corners on multiples of 0.5: every box
  // touches its 26 neighbours, so the closed-box predicate pairs every king-move neighbour:
  // 3k^2(k-1) + 6k(k-1)^2 + 4(k-1)^3 pairs.  With cell size 1 the min corners lie on cell
  // boundaries; with cell size 0.5 every box is as large as a cell and goes to the coarser level.
  const int k = 6;
  const LocalIndex n = k * k * k;
  std::vector<double> lo(3 * n), hi(3 * n);
  LocalIndex e = 0;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j)
      for (int l = 0; l < k; ++l, ++e) {
        const int ijk[3] = {i, j, l};
        for (int a = 0; a < 3; ++a) {
          lo[3 * e + a] = -1.0 + 0.5 * ijk[a];
          hi[3 * e + a] = -0.5 + 0.5 * ijk[a];
        }
      }
  const std::size_t expected =
      3 * k * k * (k - 1) + 6 * k * (k - 1) * (k - 1) + 4 * (k - 1) * (k - 1) * (k - 1);
  REQUIRE(expected == 1940);
  for (double cell : {0.0, 1.0, 0.5, 0.75}) {
    INFO("forced cell size " << cell);
    NbsOptions options;
    options.cell_size = cell;
    NbsDetector nbs(options);
    SortSweepDetector sweep;
    ThreeWay r = run_all(nbs, sweep, lo, hi, n, 0.0);
    CHECK(r.nbs.size() == expected);
    if (cell == 0.5) CHECK(nbs.stats().large_elements == n);
    if (cell == 1.0) CHECK(nbs.stats().large_elements == 0);
  }
  // A tiny gap separates the boxes: no pair without a buffer, all of them with one.
  for (LocalIndex i = 0; i < 3 * n; ++i) hi[i] -= 1e-9;
  NbsDetector nbs;
  SortSweepDetector sweep;
  CHECK(run_all(nbs, sweep, lo, hi, n, 0.0).nbs.empty());
  CHECK(run_all(nbs, sweep, lo, hi, n, 2e-9).nbs.size() == expected);
}

TEST_CASE("NBS edge case: a single huge element among small ones", "[contact][nbs]") {
  std::mt19937_64 rng(4242);
  const LocalIndex n_small = 3000;
  auto cloud = random_tets(n_small, {-10, -10, -10}, {20, 20, 20}, 0.5, 1.0, rng);
  // Element n_small covers the whole cloud; element n_small+1 covers the octant x, y, z < 0.
  const double huge_lo[2][3] = {{-12, -12, -12}, {-12, -12, -12}};
  const double huge_hi[2][3] = {{12, 12, 12}, {0, 0, 0}};
  for (int h = 0; h < 2; ++h) {
    for (int k = 0; k < 3; ++k) {
      cloud.lo.push_back(huge_lo[h][k]);
      cloud.hi.push_back(huge_hi[h][k]);
    }
  }
  const LocalIndex n = n_small + 2;
  NbsDetector nbs;
  SortSweepDetector sweep;
  ThreeWay r = run_all(nbs, sweep, cloud.lo, cloud.hi, n, 0.0);
  CHECK(nbs.stats().large_elements == 2);
  CHECK(nbs.stats().levels.size() == 2);
  LocalIndex with_whole = 0;
  for (const CandidatePair& p : r.nbs) with_whole += (p.b == n_small);
  CHECK(with_whole == n_small);  // the huge box pairs with every small element
  // Box tests stay far from N^2/2 = 4.5e6: the huge elements scan only covered cells.
  CHECK(nbs.stats().box_tests < 60 * static_cast<std::size_t>(n));
}

TEST_CASE("NBS edge case: huge elements in a sparse domain with a dense cluster",
          "[contact][nbs]") {
  // 1500 small tets in a dense 15 m cluster and 1500 spread over a 2 km cube: about 2000 cells
  // per axis, so the large-element pass cannot use a per-row table and falls back to binary
  // search (the cluster box) and to one range scan (the box covering everything).
  std::mt19937_64 rng(31);
  auto cluster = random_tets(1500, {0, 0, 0}, {15, 15, 15}, 0.5, 1.0, rng);
  auto spread = random_tets(1500, {0, 0, 0}, {2000, 2000, 2000}, 0.5, 1.0, rng);
  std::vector<double> lo = cluster.lo, hi = cluster.hi;
  lo.insert(lo.end(), spread.lo.begin(), spread.lo.end());
  hi.insert(hi.end(), spread.hi.begin(), spread.hi.end());
  const double big[3][6] = {{-1, -1, -1, 2001, 2001, 2001},    // everything
                            {2, 2, 2, 12, 12, 12},             // inside the cluster
                            {500, 500, 500, 900, 700, 1500}};  // part of the spread elements
  for (const auto& b : big) {
    lo.insert(lo.end(), b, b + 3);
    hi.insert(hi.end(), b + 3, b + 6);
  }
  const LocalIndex n = 3003;
  NbsDetector nbs;
  SortSweepDetector sweep;
  ThreeWay r = run_all(nbs, sweep, lo, hi, n, 0.01);
  CHECK(nbs.stats().large_elements == 3);
  REQUIRE(!nbs.stats().levels.empty());
  const auto& cells = nbs.stats().levels[0].cells_per_axis;
  CHECK(static_cast<double>(cells[1] + 2) * (cells[2] + 2) > 4.0 * 3000 + 4096);
  LocalIndex with_everything = 0, with_cluster_box = 0;
  for (const CandidatePair& p : r.nbs) {
    with_everything += (p.a == 3000 || p.b == 3000);
    with_cluster_box += (p.a == 3001 || p.b == 3001);
  }
  CHECK(with_everything == 3002);
  CHECK(with_cluster_box > 100);
}

TEST_CASE("NBS memory is linear in N and independent of the domain size", "[contact][nbs]") {
  std::mt19937_64 rng(5);
  const LocalIndex n = 3000;
  std::vector<CandidatePair> out;
  std::size_t bytes[2];
  int i = 0;
  for (double fraction : {0.5, 0.0005}) {  // 1000x the volume for the same N
    const double side = side_for(n, 1.0, fraction);
    auto cloud = random_tets(n, {0, 0, 0}, {side, side, side}, 0.8, 1.2, rng);
    NbsDetector nbs;
    nbs.detect(cloud.lo.data(), cloud.hi.data(), n, 0.05, out);
    bytes[i++] = nbs.stats().workspace_bytes;
    INFO("fraction " << fraction << ": " << nbs.stats().workspace_bytes / double(n)
                     << " bytes/element, cells per axis "
                     << nbs.stats().levels[0].cells_per_axis[0]);
    CHECK(nbs.stats().workspace_bytes < 160 * static_cast<std::size_t>(n));
  }
  CHECK(bytes[1] < 1.1 * bytes[0]);
}

TEST_CASE("broad phase rejects invalid input", "[contact][nbs]") {
  std::vector<double> lo{0, 0, 0, 1, 1, 1}, hi{1, 1, 1, 2, 2, 2};
  std::vector<CandidatePair> out;
  NbsDetector nbs;
  CHECK_THROWS_AS(nbs.detect(lo.data(), hi.data(), 2, -0.1, out), InputError);
  std::vector<double> bad_hi{1, 1, 1, 2, 0.5, 2};  // hi < lo on y
  CHECK_THROWS_AS(nbs.detect(lo.data(), bad_hi.data(), 2, 0.0, out), InputError);
  std::vector<double> nan_lo = lo;
  nan_lo[4] = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(nbs.detect(nan_lo.data(), hi.data(), 2, 0.0, out), NumericalFailure);
  CHECK_THROWS_AS(detect_sort_sweep(nan_lo.data(), hi.data(), 2, 0.0, out), NumericalFailure);
  CHECK_THROWS_AS(NbsDetector(NbsOptions{0.5, 0.0}), InputError);
  // After the failures the detector still works; touching boxes are a pair.
  nbs.detect(lo.data(), hi.data(), 2, 0.0, out);
  REQUIRE(out.size() == 1);
  CHECK(out[0] == CandidatePair{0, 1});
}

TEST_CASE("NBS recovers after a filter throws mid-detection", "[contact][nbs]") {
  std::mt19937_64 rng(8);
  auto cloud = random_tets(500, {0, 0, 0}, {8, 8, 8}, 0.5, 1.5, rng);
  NbsDetector nbs;
  std::vector<CandidatePair> out, expected;
  int calls = 0;
  auto throwing = [&](LocalIndex, LocalIndex) -> bool {
    if (++calls == 50) throw std::runtime_error("filter failed");
    return true;
  };
  CHECK_THROWS(nbs.detect(cloud.lo.data(), cloud.hi.data(), 500, 0.0, out, throwing));
  nbs.detect(cloud.lo.data(), cloud.hi.data(), 500, 0.0, out);
  detect_brute_force(cloud.lo.data(), cloud.hi.data(), 500, 0.0, expected);
  CHECK(out == expected);
  CHECK(expected.size() > 100);
}
