// The pair force bound (contact/pair_force_bound.hpp) and the sliver skip it allows: the bound
// holds on every pair, and on a pressed interface of matched meshes it skips the slivers next
// to the pressed pairs, never the pressed pairs.
#include <algorithm>
#include <catch2/catch.hpp>
#include <limits>
#include <random>
#include <vector>

#include "contact/pair_force_bound.hpp"
#include "contact/potential_contact_kernels.hpp"
#include "test_potential_contact_support.hpp"

using namespace fdem;
using namespace fdem::test_contact;

namespace {

// n × n cubes of edge h side by side in x and y, each split into the 6 tets around its diagonal.
std::vector<TetCorners> cube_layer(int n, double h, const Vec3& origin) {
  static constexpr int kAxisOrder[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                           {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  std::vector<TetCorners> tets;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (const auto& order : kAxisOrder) {
        TetCorners t;
        Vec3 x = origin + Vec3(i * h, j * h, 0.0);
        t.x[0] = x;
        for (int k = 0; k < 3; ++k) {
          x[order[k]] += h;
          t.x[k + 1] = x;
        }
        tets.push_back(t);
      }
  return tets;
}

// Two layers of 3 × 3 cubes of 0.05 m, the upper sunk `depth` of the edge into the lower: with
// matched meshes, then shifted across the interface.
template <class Body>
void for_pressed_interfaces(double depth, Body body) {
  const double h = 0.05;
  const auto lower = cube_layer(3, h, Vec3(0, 0, -h));
  for (const double shift : {0.0, 0.37}) {
    INFO("shift " << shift << " depth " << depth);
    body(cube_layer(3, h, Vec3(shift * h, 0.3 * shift * h, -depth * h)), lower);
  }
}

// The piece bounds as negligible_parts computes them: on the slab depths narrowed by the caps
// (`reach`, narrow_slab_depths).
void kernel_piece_bounds(const TetPairFrame& frame, double (&reach)[8], double (&piece)[8]) {
  double mu[8];
  slab_depths(frame, mu);
  narrow_slab_depths(frame, mu, reach);
  const FrameMetrics metrics(frame);
  piece_force_bounds(metrics.pair(), reach, pair_force_bound(frame, metrics.pair(), reach, 1.0),
                     std::numeric_limits<double>::infinity(), piece);
}

struct PairCheck {
  int pairs = 0, violations = 0;
};

// Every pair that passes the face planes: the exact kernel stays within the bound (plus a
// round-off allowance of 1e-14 of the full-overlap scale p ℓ², p ℓ³, ℓ³).
void check_bound(const TetCorners& c, const TetCorners& t, double penalty, PairCheck& check) {
  TetPairFrame frame;
  if (!prepare_tet_pair(c, t, frame)) return;
  const PairForceBound bound = pair_force_bound(frame, penalty);
  const ContactPairResult exact = potential_contact(c, t, penalty);
  const double l = bound.length;
  ++check.pairs;
  const bool holds =
      largest_nodal_force(exact) <= bound.nodal_force * (1 + 1e-9) + 1e-14 * penalty * l * l &&
      exact.energy <= bound.energy * (1 + 1e-9) + 1e-14 * penalty * l * l * l &&
      exact.overlap_volume <= bound.volume * (1 + 1e-9) + 1e-14 * l * l * l;
  if (!holds) ++check.violations;
}

}  // namespace

TEST_CASE("the pair force bound holds on random overlapping pairs", "[contact]") {
  std::mt19937_64 rng(20261129);
  PairCheck check;
  for (int i = 0; i < 4000; ++i) {
    TetCorners c, t;
    random_overlapping_pair(rng, Vec3(0.3, -0.2, 0.1), c, t, 2.0e9);
    check_bound(c, t, 2.0e9, check);
  }
  CHECK(check.pairs == 4000);
  CHECK(check.violations == 0);
}

TEST_CASE("the pair force bound holds across pressed interfaces from 1e-10 to 1e-2 deep",
          "[contact]") {
  const double penalty = 5.0e10;
  for (const double depth : {1e-10, 1e-8, 1e-6, 1e-4, 1e-2})
    for_pressed_interfaces(
        depth, [&](const std::vector<TetCorners>& upper, const std::vector<TetCorners>& lower) {
          PairCheck check;
          for (const TetCorners& c : upper)
            for (const TetCorners& t : lower) check_bound(c, t, penalty, check);
          CHECK(check.pairs > 200);
          CHECK(check.violations == 0);
        });
}

TEST_CASE("matched interface pressed 1e-6 deep: the slivers are skipped and no pressed pair",
          "[contact]") {
  // Upper cubes sunk by 1e-6 h into the lower ones, meshes matched at the interface.  The pairs
  // under one shared face carry the load; the tets beside them across an edge or a corner of the
  // footprint overlap in slivers of 1e-6 h in two directions and carry ~(1e-6)² p h².
  const double h = 1.0, penalty = 1.0, tolerance = 1e-9;
  const auto lower = cube_layer(2, h, Vec3(0, 0, -h));
  const auto upper = cube_layer(2, h, Vec3(0, 0, -1e-6 * h));
  double largest = 0.0;
  for (const TetCorners& c : upper)
    for (const TetCorners& t : lower)
      largest = std::max(largest, largest_nodal_force(potential_contact(c, t, penalty)));
  int pressed = 0, slivers = 0, slivers_skipped = 0, pressed_skipped = 0, differ = 0;
  int pieces_left_out = 0;
  double loosest = 0.0;  // bound / exact force over the slivers
  for (const TetCorners& c : upper)
    for (const TetCorners& t : lower) {
      const ContactPairResult exact = potential_contact(c, t, penalty);
      const ContactPairResult skipping = potential_contact(c, t, penalty, tolerance);
      const double force = largest_nodal_force(exact);
      const bool skipped = exact.overlapping && !skipping.overlapping;
      if (exact.overlapping &&
          !skipped) {  // an evaluated pair is the exact kernel's to within its left-out pieces
        TetPairFrame frame;
        REQUIRE(prepare_tet_pair(c, t, frame));
        double reach[8], piece[8];
        kernel_piece_bounds(frame, reach, piece);
        const unsigned left_out = negligible_parts(frame, tolerance);
        double allowed = 0.0;
        for (int k = 0; k < 8; ++k)
          if ((left_out >> k) & 1u) {
            allowed += penalty * piece[k];
            ++pieces_left_out;
          }
        differ += largest_nodal_force_difference(exact, skipping) >
                  allowed * (1 + 1e-9) + 1e-15 * largest;
      }
      if (force > 1e-3 * largest) {
        ++pressed;
        pressed_skipped += skipped;
      } else if (force > 1e-9 * largest) {
        ++slivers;
        slivers_skipped += skipped;
        TetPairFrame frame;
        REQUIRE(prepare_tet_pair(c, t, frame));
        loosest = std::max(loosest, pair_force_bound(frame, penalty).nodal_force / force);
      }
    }
  CHECK(pressed == 8);  // 4 cubes, 2 triangles on each top face: one upper tet on each
  CHECK(pressed_skipped == 0);
  CHECK(slivers == 16);
  CHECK(slivers_skipped == slivers);
  CHECK(differ == 0);
  // Each pressed pair leaves out the pieces of the sub-tets beside its face on either side.
  CHECK(pieces_left_out >= 2 * pressed);
  // The bound is rigorous but not tight: within 100 × the slivers' exact forces (39× measured).
  CHECK(loosest < 100.0);
}

TEST_CASE("a corner poking into a corner is bounded by the cube of its depth and skipped",
          "[contact]") {
  // Two tets corner to corner, the upper one's cone inside the lower one's reflected through its
  // apex, sunk d into it: the overlap is ~d³.  The lower tet has three slabs d thin (the faces
  // through its apex), so a parallelepiped of three bounds it (pair_force_bound.hpp); the prism
  // of two stays a whole edge long, d² h.
  const Vec3 edge[3] = {Vec3(1.0, 0.0, -1.0), Vec3(-0.5, 0.866, -1.0), Vec3(-0.5, -0.866, -1.0)};
  for (const double depth : {1e-2, 1e-3, 1e-4, 1e-6}) {
    TetCorners lower, upper;
    lower.x[0] = Vec3(0.1, 0.2, 0.3);
    upper.x[0] = lower.x[0] - Vec3(0.0, 0.0, depth);
    for (int k = 0; k < 3; ++k) {
      lower.x[k + 1] = lower.x[0] + edge[k];
      const Vec3& e = edge[(k + 1) % 3];  // the other orientation, still a tet
      upper.x[k + 1] = upper.x[0] + Vec3(-0.7 * e.x(), -0.7 * e.y(), 1.0);  // a narrower cone
    }
    const ContactPairResult exact = potential_contact(upper, lower, 1.0);
    TetPairFrame frame;
    REQUIRE(prepare_tet_pair(upper, lower, frame));
    const PairForceBound bound = pair_force_bound(frame, 1.0);
    INFO("depth " << depth << ": overlap " << exact.overlap_volume << ", bound " << bound.volume);
    CHECK(exact.overlap_volume > 0.01 * depth * depth * depth);
    CHECK(exact.overlap_volume < depth * depth * depth);
    CHECK(exact.overlap_volume <= bound.volume * (1 + 1e-9));
    CHECK(bound.volume < 100.0 * exact.overlap_volume);
    CHECK(largest_nodal_force(exact) <= bound.nodal_force * (1 + 1e-9));
    // 1e-4 deep and less it is skipped at the default tolerance (its limit 1e-3 · mu p ℓ², mu the
    // thinnest slab, ~1e-7 p ℓ² there): the bound's nodal force is 0.74 d² p (with two slabs
    // only it was 1.3 d p, measured).
    if (depth <= 1e-4) CHECK(negligible_parts(frame, 1e-6) == kEveryPiece);
  }
}

TEST_CASE("meshes shifted across a pressed interface: slivers skipped, no pressed pair",
          "[contact]") {
  // The upper layer shifted by (0.37, 0.11) h and sunk 1e-6 h: its tets meet the lower ones in
  // pressed faces of every footprint, and (the tets that reach the interface with an edge or a
  // corner only) in slivers 1e-6 h thin in two directions.  The slabs alone cannot tell those
  // slivers: the other tet's far corners lie deep in every slab of the sliver's tet.  The caps
  // beyond the pressed plane (narrow_slab_depths) can.
  const double h = 1.0, penalty = 1.0, tolerance = 1e-9;
  const auto lower = cube_layer(2, h, Vec3(0, 0, -h));
  const auto upper = cube_layer(2, h, Vec3(0.37 * h, 0.11 * h, -1e-6 * h));
  double largest = 0.0;
  for (const TetCorners& c : upper)
    for (const TetCorners& t : lower)
      largest = std::max(largest, largest_nodal_force(potential_contact(c, t, penalty)));
  int pressed = 0, pressed_skipped = 0, slivers = 0, slivers_skipped = 0, above_limit = 0;
  for (const TetCorners& c : upper)
    for (const TetCorners& t : lower) {
      const ContactPairResult exact = potential_contact(c, t, penalty);
      if (!exact.overlapping) continue;
      const bool skipped = !potential_contact(c, t, penalty, tolerance).overlapping;
      const double force = largest_nodal_force(exact);
      if (force > 1e-3 * largest) {
        ++pressed;
        pressed_skipped += skipped;
      } else {
        ++slivers;
        slivers_skipped += skipped;
      }
      // A pair skipped whole is proven below tolerance · p · ℓ² (ℓ ≤ √3 h here).
      above_limit += skipped && force > tolerance * penalty * 3.0 * h * h;
    }
  CHECK(pressed >= 8);
  CHECK(pressed_skipped == 0);
  CHECK(slivers > 20);
  CHECK(slivers_skipped > slivers / 2);
  CHECK(above_limit == 0);
}

TEST_CASE("a pressed face is never skipped, from round-off depth to deep, at the largest tolerance",
          "[contact]") {
  // The second condition of negligible_parts (below 1/1000 of what a face pressed as deep
  // carries): without it a face contact starting from touching would be skipped until its force
  // reached the tolerance, then enter with its energy at once.
  const double h = 1.0, penalty = 1.0;
  const auto lower = cube_layer(2, h, Vec3(0, 0, -h));
  for (const double depth : {1e-14, 1e-12, 1e-10, 1e-8, 1e-6, 1e-4, 1e-2}) {
    const auto upper = cube_layer(2, h, Vec3(0, 0, -depth * h));
    double largest = 0.0;
    for (const TetCorners& c : upper)
      for (const TetCorners& t : lower)
        largest = std::max(largest, largest_nodal_force(potential_contact(c, t, penalty)));
    int pressed = 0, kept = 0;
    for (const TetCorners& c : upper)
      for (const TetCorners& t : lower) {
        const ContactPairResult exact = potential_contact(c, t, penalty);
        if (largest_nodal_force(exact) <= 1e-3 * largest) continue;
        ++pressed;
        kept += potential_contact(c, t, penalty, 1e-6).overlapping;
      }
    INFO("depth " << depth);
    CHECK(pressed >= 8);  // the 8 pressed faces (1e-2 deep, the slivers carry more than 1e-3)
    CHECK(kept == pressed);
  }
}

namespace {

struct PieceCheck {
  int pieces = 0, violations = 0;
};

// Each piece with a bound, left out alone: no nodal force moves by more than p times its bound,
// and the energy by no more than p m_T bound / G_T (its volume is below bound / 4 G_T, and the
// potential on it below 4 m_T), plus 1e-14 of the full-overlap scales for round-off.
void check_pieces(const TetCorners& c, const TetCorners& t, double penalty, PieceCheck& check) {
  TetPairFrame frame;
  if (!prepare_tet_pair(c, t, frame)) return;
  double reach[8], piece[8];
  kernel_piece_bounds(frame, reach, piece);
  const ContactPairResult exact = potential_contact(c, t, penalty);
  const double l = pair_force_bound(frame, penalty).length;
  for (int k = 0; k < 8; ++k) {
    if (!std::isfinite(piece[k])) continue;
    const int T = k / 4;
    const double thinnest_own = *std::min_element(reach + 4 * T, reach + 4 * T + 4);
    double largest_gradient = 0.0;
    for (int a = 0; a < 4; ++a)
      largest_gradient = std::max(largest_gradient, frame.map[T].gradient[a].norm());
    const ContactPairResult without = potential_contact_without(c, t, penalty, 1u << k);
    ++check.pieces;
    const bool holds = largest_nodal_force_difference(exact, without) <=
                           penalty * piece[k] * (1 + 1e-9) + 1e-14 * penalty * l * l &&
                       std::abs(exact.energy - without.energy) <=
                           penalty * thinnest_own * piece[k] / largest_gradient * (1 + 1e-9) +
                               1e-14 * penalty * l * l * l;
    if (!holds) ++check.violations;
  }
}

}  // namespace

TEST_CASE("a piece left out moves no nodal force beyond its bound", "[contact]") {
  const double penalty = 5.0e10;
  for (const double depth : {1e-10, 1e-8, 1e-6, 1e-4, 1e-3})
    for_pressed_interfaces(
        depth, [&](const std::vector<TetCorners>& upper, const std::vector<TetCorners>& lower) {
          PieceCheck check;
          for (const TetCorners& c : upper)
            for (const TetCorners& t : lower) check_pieces(c, t, penalty, check);
          CHECK(check.pieces > 200);
          CHECK(check.violations == 0);
        });
  std::mt19937_64 rng(20261130);
  PieceCheck random;
  for (int i = 0; i < 4000; ++i) {
    TetCorners c, t;
    random_overlapping_pair(rng, Vec3(0.3, -0.2, 0.1), c, t, 2.0e9);
    check_pieces(c, t, 2.0e9, random);
  }
  CHECK(random.pieces > 20);  // random pairs are rarely thin: 52 of their pieces have a bound
  CHECK(random.violations == 0);
}

TEST_CASE("with pieces left out the forces are the exact gradient of the kept pieces' energy",
          "[contact]") {
  // Central differences of U (step 1e-6 of the size) against the forces, within 1e-6 of the
  // largest nodal force, as for the whole kernel: the flux each left-out piece leaves uncancelled
  // is added, so the kept pieces form a conservative contact of their own.
  std::mt19937_64 rng(20261129);
  const double penalty = 7.0e8, h = 1e-6;
  const unsigned masks[] = {0x02u, 0x08u, 0x10u, 0x40u, 0x06u, 0x60u, 0x91u, 0x3Cu};
  int checked = 0, failed = 0;
  double worst = 0.0;
  for (int trial = 0; trial < 60; ++trial) {
    TetCorners c, t;
    random_overlapping_pair(rng, Vec3(0.3 * trial, 1.0, -0.5 * trial), c, t, penalty);
    for (const unsigned mask : masks) {
      const ContactPairResult r = potential_contact_without(c, t, penalty, mask);
      if (!r.overlapping) continue;
      double err = 0.0;
      for (int side = 0; side < 2; ++side)
        for (int v = 0; v < 4; ++v)
          for (int k = 0; k < 3; ++k) {
            TetCorners cp = c, cm = c, tp = t, tm = t;
            (side == 0 ? cp : tp).x[v][k] += h;
            (side == 0 ? cm : tm).x[v][k] -= h;
            const double numerical = -(potential_contact_without(cp, tp, penalty, mask).energy -
                                       potential_contact_without(cm, tm, penalty, mask).energy) /
                                     (2.0 * h);
            const Vec3& f = side == 0 ? r.force_contactor[v] : r.force_target[v];
            err = std::max(err, std::abs(numerical - f[k]));
          }
      worst = std::max(worst, err / largest_nodal_force(r));
      failed += err > 1e-6 * largest_nodal_force(r);
      ++checked;
    }
  }
  INFO("worst |f + dU/dx| / max|f| = " << worst);
  CHECK(checked > 300);
  CHECK(failed == 0);
}

TEST_CASE("the bounds hold where a fine mesh presses on a coarse one, and its slivers are skipped",
          "[contact]") {
  // 5 × 5 cubes of 0.04 m pressed into 1 × 1 of 0.2 m, shifted: the fine tets' slabs are thin
  // only through the caps beyond the coarse tets' faces (narrow_slab_depths), which the pair and
  // piece bounds then use.  Both stay above the exact kernel, from 1e-9 to 1e-3 of the fine size.
  const double penalty = 3.0e9;
  const auto coarse = cube_layer(1, 0.2, Vec3(0, 0, -0.2));
  int skipped_pairs = 0, pressed_skipped = 0;
  for (const double depth : {1e-9, 1e-7, 1e-5, 1e-3}) {
    INFO("depth " << depth);
    const auto fine = cube_layer(5, 0.04, Vec3(0.013, 0.007, -depth * 0.04));
    PairCheck pairs;
    PieceCheck pieces;
    double largest = 0.0;
    for (const TetCorners& c : fine)
      for (const TetCorners& t : coarse) {
        check_bound(c, t, penalty, pairs);
        check_bound(t, c, penalty, pairs);
        check_pieces(c, t, penalty, pieces);
        check_pieces(t, c, penalty, pieces);
        largest = std::max(largest, largest_nodal_force(potential_contact(c, t, penalty)));
      }
    CHECK(pairs.violations == 0);
    CHECK(pieces.violations == 0);
    CHECK(pieces.pieces > 50);
    for (const TetCorners& c : fine)
      for (const TetCorners& t : coarse) {
        const ContactPairResult exact = potential_contact(c, t, penalty);
        const bool skipped =
            exact.overlapping && !potential_contact(c, t, penalty, 1e-6).overlapping;
        skipped_pairs += skipped;
        pressed_skipped += skipped && largest_nodal_force(exact) > 1e-3 * largest;
      }
  }
  CHECK(skipped_pairs > 100);
  CHECK(pressed_skipped == 0);
}

namespace {
// negligible_parts as it was before the caps alone could decide a tet: every tet's pieces bounded
// with their prisms.
unsigned negligible_parts_with_every_prism(const TetPairFrame& frame, double tolerance) {
  double mu[8];
  const double thinnest = slab_depths(frame, mu);
  if (!(thinnest < 1e-3)) return 0;
  const double share = std::min(tolerance, kPressedFaceShare * thinnest);
  const FrameMetrics metrics(frame);
  const PairForceBound bound = pair_force_bound(frame, metrics.pair(), mu, 1.0, share);
  const double limit = share * bound.length * bound.length;
  if (bound.nodal_force <= limit) return kEveryPiece;
  double reach[8], piece[8];
  if (narrow_slab_depths(frame, mu, reach))
    piece_force_bounds(metrics.pair(), reach, pair_force_bound(frame, metrics.pair(), reach, 1.0),
                       limit, piece);
  else
    piece_force_bounds(metrics.pair(), mu, bound, limit, piece);
  unsigned skipped = 0;
  for (int k = 0; k < 8; ++k) skipped |= piece[k] <= limit ? 1u << k : 0u;
  return skipped;
}
}  // namespace

TEST_CASE("the caps alone leave out the same pieces as every piece's prisms", "[contact]") {
  // Pressed interfaces of matched and shifted meshes from 1e-9 to 1e-3 deep, and random pairs.
  int pairs = 0, differ = 0, all_left_out = 0, some_kept = 0;
  const auto compare = [&](const TetCorners& c, const TetCorners& t, double tolerance) {
    TetPairFrame frame;
    if (!prepare_tet_pair(c, t, frame)) return;
    const unsigned now = negligible_parts(frame, tolerance);
    const unsigned before = negligible_parts_with_every_prism(frame, tolerance);
    ++pairs;
    differ += now != before;
    all_left_out += now == kEveryPiece;
    some_kept += now != 0 && now != kEveryPiece;
  };
  for (const double depth : {1e-9, 1e-7, 1e-5, 1e-3})
    for_pressed_interfaces(
        depth, [&](const std::vector<TetCorners>& upper, const std::vector<TetCorners>& lower) {
          for (const TetCorners& c : upper)
            for (const TetCorners& t : lower)
              for (const double tolerance : {1e-9, 1e-6, 1e-3}) compare(c, t, tolerance);
        });
  std::mt19937_64 rng(5);
  for (int p = 0; p < 2000; ++p) {
    TetCorners c, t;
    random_overlapping_pair(rng, Vec3::Zero(), c, t);
    compare(c, t, 1e-6);
  }
  INFO(pairs << " pairs: " << all_left_out << " left out whole, " << some_kept
             << " with some pieces kept");
  CHECK(differ == 0);
  CHECK(all_left_out > 100);
  CHECK(some_kept > 100);
}
