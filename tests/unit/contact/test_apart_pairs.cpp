// Pairs apart by a known gap (contact/apart_pairs.hpp): every gap the kernel and the stage report
// is at most the tets' exact distance, a pair whose tets moved less than its gap is still found
// apart by the kernel, and the travel sums stay upper bounds.
#include <algorithm>
#include <catch2/catch.hpp>
#include <limits>
#include <random>

#include "contact/apart_pairs.hpp"
#include "contact/clip_replay.hpp"
#include "contact/potential_contact_kernels.hpp"
#include "contact/tet_distance.hpp"
#include "test_potential_contact_support.hpp"

using namespace fdem;
using namespace fdem::test_contact;

namespace {

void local_corners(const TetCorners& t, Vec3 (&x)[4]) {
  for (int c = 0; c < 4; ++c) x[c] = t.x[c];
}

double exact_distance(const TetCorners& a, const TetCorners& b) {
  Vec3 pa[4], pb[4];
  local_corners(a, pa);
  local_corners(b, pb);
  return tet_distance(pa, pb);
}

// The gap the kernel reports for a pair (through its memo), as the contact stage sees it: first
// with no memory (the face planes), then, as the stage does at the next step, with the memo of
// a pair that clipped to nothing (the edge–edge axes).
double kernel_gap(const TetCorners& c, const TetCorners& t, bool& overlapping) {
  TetGeometry gc, gt;
  compute_tet_geometry(c, gc);
  compute_tet_geometry(t, gt);
  PreparedContactor prepared;
  prepare_contactor(gc, prepared);
  ClipMemo memo;
  overlapping = potential_contact(prepared, gt, 1.0, 0.0, &memo).overlapping;
  if (memo.apart_gap > 0.0 || overlapping) return memo.apart_gap;
  ClipMemo again;
  again.apart_before =
      memo.apart_now == ClipMemo::kNotApart ? ClipMemo::kClippedEmpty : memo.apart_now;
  potential_contact(prepared, gt, 1.0, 0.0, &again);
  return again.apart_gap;
}

TetBox box_of(const TetCorners& t) {
  return tet_box(t);
}

}  // namespace

TEST_CASE("gaps from the boxes, a face plane or an edge axis never exceed the exact distance",
          "[contact][apart_pairs]") {
  std::mt19937_64 rng(20261130);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int with_box_gap = 0, with_kernel_gap = 0, pairs = 0;
  double closest_ratio = 0.0;  // largest gap / distance seen
  for (int trial = 0; trial < 20000; ++trial) {
    const TetCorners t = random_tet(rng, 1.0, Vec3::Zero());
    // Contactors around the target, from overlapping to a tet size apart.
    const TetCorners c =
        random_tet(rng, 0.3 + 1.7 * u(rng), (0.3 + 1.2 * u(rng)) * random_unit(rng));
    const double distance = exact_distance(c, t);
    bool overlapping = false;
    const double gap = kernel_gap(c, t, overlapping);
    const double boxes = box_gap(box_of(c), box_of(t));
    ++pairs;
    with_kernel_gap += gap > 0.0;
    with_box_gap += boxes > 0.0;
    if (overlapping) CHECK(gap == 0.0);
    CHECK(gap <= distance * (1.0 + 1e-12));
    CHECK(boxes <= distance * (1.0 + 1e-12));
    if (distance > 0.0) closest_ratio = std::max(closest_ratio, std::max(gap, boxes) / distance);
  }
  INFO(pairs << " pairs: " << with_kernel_gap << " with a kernel gap, " << with_box_gap
             << " with a box gap; largest gap / distance " << closest_ratio);
  CHECK(with_kernel_gap > pairs / 10);
  CHECK(with_box_gap > pairs / 20);
  CHECK(closest_ratio > 0.5);  // the gaps are not trivially small
}

TEST_CASE("tets moved less than their gap in all are still found apart by the kernel",
          "[contact][apart_pairs]") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0), s(-1.0, 1.0);
  int skipped_steps = 0, checked = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    TetCorners t = random_tet(rng, 1.0, Vec3::Zero());
    TetCorners c = random_tet(rng, 0.3 + 1.7 * u(rng), (0.4 + 1.2 * u(rng)) * random_unit(rng));
    bool overlapping = false;
    const double gap = std::max(kernel_gap(c, t, overlapping), box_gap(box_of(c), box_of(t)));
    if (!(gap > 0.0)) continue;
    // The stage's bookkeeping over steps of random corner motion (each corner its own), until
    // the pair is no longer sure to be apart: every step it skips, the kernel finds it apart.
    ApartPairs apart;
    apart.reset(2);
    apart.found(0, 1, 0, 1, gap);
    const double step = gap * (0.02 + 0.3 * u(rng));
    for (int k = 0; k < 100; ++k) {
      TetCorners c2 = c, t2 = t;
      for (int v = 0; v < 4; ++v) {
        c2.x[v] += step * u(rng) * random_unit(rng);
        t2.x[v] += step * u(rng) * random_unit(rng);
      }
      apart.moved(0, c, c2);
      apart.moved(1, t, t2);
      c = c2;
      t = t2;
      if (!apart.still_apart(0, 0, 1)) break;
      ++skipped_steps;
      bool now_overlapping = true;
      kernel_gap(c, t, now_overlapping);
      CHECK_FALSE(now_overlapping);
      CHECK(exact_distance(c, t) > 0.0);
      ++checked;
    }
  }
  INFO(checked << " skipped steps checked");
  CHECK(skipped_steps > 3000);
}

TEST_CASE("travel sums stay upper bounds: tiny steps beside a long travel are not lost",
          "[contact][apart_pairs]") {
  // Tet b went 1 m in one step before the pair was found apart by 2 nm; then tet a moves by 1e-14
  // m per step, about 50 units in the last place of the pair's travel sum (~1 m).  The skip must
  // end before a has gone the gap, and not far before.
  ApartPairs apart;
  apart.reset(2);
  TetCorners a, b, b_moved;
  for (int v = 0; v < 4; ++v) {
    a.x[v] = Vec3(1000.0 + v, 0, 0);
    b.x[v] = Vec3(2000.0 + v, 0, 0);
    b_moved.x[v] = b.x[v] + Vec3(0, 1.0, 0);
  }
  apart.moved(0, a, a);
  apart.moved(1, b, b_moved);
  const double gap = 2e-9;  // m
  apart.found(0, 1, 0, 1, gap);
  TetCorners moved_a = a;
  double travelled = 0.0;
  long steps = 0;
  while (apart.still_apart(0, 0, 1) && steps < 10000000) {
    TetCorners next = moved_a;
    for (int v = 0; v < 4; ++v) next.x[v].z() += 1e-14;
    travelled += (next.x[0] - moved_a.x[0]).norm();
    apart.moved(0, moved_a, next);
    apart.moved(1, b_moved, b_moved);
    moved_a = next;
    ++steps;
  }
  INFO(steps << " steps, travelled " << travelled << " m");
  CHECK(travelled <= gap);
  CHECK(travelled > 0.8 * gap);  // nor is the bound loose
  // NaN corners: never again sure to be apart.
  ApartPairs broken;
  broken.reset(2);
  broken.found(0, 1, 0, 1, 1.0);
  TetCorners nan_corners = a;
  nan_corners.x[2].x() = std::numeric_limits<double>::quiet_NaN();
  broken.moved(0, a, nan_corners);
  CHECK_FALSE(broken.still_apart(0, 0, 1));
}
