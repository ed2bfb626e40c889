// Potential-based tet-tet contact: exact gradient, conservation, analytic values, rejection.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "contact/potential_contact_kernels.hpp"
#include "test_potential_contact_support.hpp"

using namespace fdem;
using namespace fdem::test_contact;

namespace {

TetCorners unit_tet() {
  TetCorners t;
  t.x[0] = Vec3(0, 0, 0);
  t.x[1] = Vec3(1, 0, 0);
  t.x[2] = Vec3(0, 1, 0);
  t.x[3] = Vec3(0, 0, 1);
  return t;
}

TetCorners transformed(const TetCorners& t, const Mat3& rot, const Vec3& shift) {
  TetCorners r;
  for (int v = 0; v < 4; ++v) r.x[v] = rot * t.x[v] + shift;
  return r;
}

// Central-difference gradient of U with respect to every node coordinate (contactor then target).
void numerical_forces(const TetCorners& c, const TetCorners& t, double penalty, double h,
                      Vec3 (&fc)[4], Vec3 (&ft)[4]) {
  for (int side = 0; side < 2; ++side) {
    for (int v = 0; v < 4; ++v) {
      for (int k = 0; k < 3; ++k) {
        TetCorners cp = c, cm = c, tp = t, tm = t;
        TetCorners& p = side == 0 ? cp : tp;
        TetCorners& m = side == 0 ? cm : tm;
        p.x[v][k] += h;
        m.x[v][k] -= h;
        const double up = potential_contact_unculled(cp, tp, penalty).energy;
        const double um = potential_contact_unculled(cm, tm, penalty).energy;
        (side == 0 ? fc : ft)[v][k] = -(up - um) / (2.0 * h);
      }
    }
  }
}

}  // namespace

TEST_CASE("coincident identical tets: U = 2 p int(phi) = p V / 2, zero resultant",
          "[potential_contact]") {
  // ∫_tet 4 min(lambda) dV: each sub-tet (volume V/4) has phi = 4 lambda_i with lambda_i = 1/16
  // at its centroid, so ∫ = 4 * (1/16) * V/4 * 4 = V/4 and U = p (V/4 + V/4).
  std::mt19937_64 rng(11);
  const double penalty = 3.0e9;
  for (int trial = 0; trial < 20; ++trial) {
    const TetCorners t = random_tet(rng, 0.01 + trial * 0.05, Vec3(trial, -2.0 * trial, 5.0));
    const double volume = std::abs(signed_volume(t));
    TetCorners swapped = t;  // same tet, opposite node order
    std::swap(swapped.x[0], swapped.x[3]);
    for (const TetCorners* c :
         {static_cast<const TetCorners*>(&t), static_cast<const TetCorners*>(&swapped)}) {
      const ContactPairResult r = potential_contact(*c, t, penalty);
      REQUIRE(r.overlapping);
      CHECK(r.overlap_volume == Approx(volume).epsilon(1e-12));
      CHECK(r.energy == Approx(0.5 * penalty * volume).epsilon(1e-12));
      CHECK(tet_potential_integral(volume) == Approx(0.25 * volume));
      Vec3 resultant = Vec3::Zero();
      for (int v = 0; v < 4; ++v) resultant += r.force_contactor[v];
      CHECK(resultant.norm() <= 1e-12 * largest_nodal_force(r));
      CHECK((r.centroid - tet_centroid(t)).norm() <= 1e-12 * std::cbrt(volume));
    }
  }
}

TEST_CASE("forces are the exact negative gradient of U (finite differences)",
          "[potential_contact]") {
  // Tolerance: 1e-6 of the largest nodal force, per component; step h = 1e-6 * size.
  std::mt19937_64 rng(2024);
  const double penalty = 7.0e8;
  double worst = 0.0;
  int checked = 0;
  for (int trial = 0; trial < 150; ++trial) {
    TetCorners c, t;
    random_overlapping_pair(rng, Vec3(0.3 * trial, 1.0, -0.5 * trial), c, t, penalty);
    const ContactPairResult r = potential_contact(c, t, penalty);
    REQUIRE(r.overlapping);
    Vec3 fc[4], ft[4];
    numerical_forces(c, t, penalty, 1e-6, fc, ft);
    const double scale = largest_nodal_force(r);
    double err = 0.0;
    for (int v = 0; v < 4; ++v) {
      err = std::max(err, (fc[v] - r.force_contactor[v]).cwiseAbs().maxCoeff());
      err = std::max(err, (ft[v] - r.force_target[v]).cwiseAbs().maxCoeff());
    }
    worst = std::max(worst, err / scale);
    CHECK(err <= 1e-6 * scale);
    ++checked;
  }
  std::printf("[fd] %d configurations, worst |f - (-dU/dX)| / max|f| = %.3e\n", checked, worst);
}

TEST_CASE("linear and angular momentum are conserved to round-off", "[potential_contact]") {
  // Tolerance: |sum f| <= 1e-12 max|f| and |sum x × f| <= 1e-12 max|f| L (L = 1: target size,
  // moments about the target centroid), including slivers of overlap down to V ~ 1e-9 V_tet.
  std::mt19937_64 rng(7);
  double worst_f = 0.0, worst_m = 0.0;
  for (int trial = 0; trial < 500; ++trial) {
    TetCorners c, t;
    random_overlapping_pair(rng, Vec3(-4.0 + 0.01 * trial, 2.0, 0.0), c, t);
    const ContactPairResult r = potential_contact(c, t, 1.0);
    REQUIRE(r.overlapping);
    const Vec3 ref = tet_centroid(t);
    Vec3 sum_f = Vec3::Zero(), sum_m = Vec3::Zero();
    for (int v = 0; v < 4; ++v) {
      sum_f += r.force_contactor[v] + r.force_target[v];
      sum_m += (c.x[v] - ref).cross(r.force_contactor[v]) + (t.x[v] - ref).cross(r.force_target[v]);
    }
    const double scale = largest_nodal_force(r);
    worst_f = std::max(worst_f, sum_f.norm() / scale);
    worst_m = std::max(worst_m, sum_m.norm() / scale);
    CHECK(sum_f.norm() <= 1e-12 * scale);
    CHECK(sum_m.norm() <= 1e-12 * scale);
  }
  std::printf("[momentum] 500 pairs: worst |sum f|/max|f| = %.3e, |sum x*f|/(max|f| L) = %.3e\n",
              worst_f, worst_m);
}

TEST_CASE("swapping contactor and target swaps the forces and keeps U", "[potential_contact]") {
  // Tolerance: 1e-12 relative (the two orders integrate the same pieces in different frames).
  std::mt19937_64 rng(99);
  for (int trial = 0; trial < 200; ++trial) {
    TetCorners c, t;
    random_overlapping_pair(rng, Vec3(1.0, 2.0, 3.0), c, t);
    const ContactPairResult a = potential_contact(c, t, 2.5);
    const ContactPairResult b = potential_contact(t, c, 2.5);
    REQUIRE(b.overlapping);
    CHECK(b.energy == Approx(a.energy).epsilon(1e-12));
    CHECK(b.overlap_volume == Approx(a.overlap_volume).epsilon(1e-12));
    const double scale = largest_nodal_force(a);
    for (int v = 0; v < 4; ++v) {
      CHECK((b.force_target[v] - a.force_contactor[v]).norm() <= 1e-12 * scale);
      CHECK((b.force_contactor[v] - a.force_target[v]).norm() <= 1e-12 * scale);
    }
    CHECK((b.centroid - a.centroid).norm() <= 1e-12);
    CHECK(b.normal.dot(a.normal) == Approx(-1.0).epsilon(1e-12));
  }
}

TEST_CASE("small tet pushed through a face of a large tet: closed-form V, U and force",
          "[potential_contact]") {
  // Target: large tet, face z = 0 on top (apex at depth H below), so near that face's middle
  // phi_t = 4 lambda = -4 z / H.  Contactor: apex up, base parallel to z = 0 at depth d.  With
  // delta = d / h (h: contactor height, delta <= 1/4) the overlap is the contactor's slab of
  // height d above its base:
  //   V = A h (1 - (1 - delta)^3) / 3
  //   ∫ phi_t = (4/H) A h^2 (delta^2/2 - delta^3/3 + delta^4/12)
  //   ∫ phi_c = 4 V_c G(delta),  G = (1 - (1-4 delta)^4)/16 - ((1-delta)^4 - (1-4 delta)^4)/12
  // (G = E[min lambda; lambda_0 <= delta] over the simplex, lambda_0 Beta(1,3) distributed).
  // Resultant on the contactor: +z, magnitude dU/dd; no lateral component (U is invariant under
  // lateral shifts while the slab stays in the face's sub-tet).  Tolerance (relative):
  // 1e-13 + 2e-14 h/d: the barycentric values of the 20 m target carry eps-sized absolute
  // errors, so a slab of thickness d is known to ~eps * (target size) / d.
  const double big_h = 20.0;
  TetCorners target;
  target.x[0] = Vec3(0.0, 0.0, -big_h);
  target.x[1] = Vec3(-10.0, -8.0, 0.0);
  target.x[2] = Vec3(11.0, -7.0, 0.0);
  target.x[3] = Vec3(0.5, 12.0, 0.0);
  const double h = 0.3;
  const Vec3 base[3] = {Vec3(-0.1, -0.08, 0.0), Vec3(0.12, -0.05, 0.0), Vec3(0.0, 0.11, 0.0)};
  const double area = 0.5 * (base[1] - base[0]).cross(base[2] - base[0]).norm();
  const double contactor_volume = area * h / 3.0;
  const double penalty = 5.0e9;
  for (double d : {1e-6, 1e-4, 0.003, 0.02, 0.05, 0.075}) {
    TetCorners c;
    c.x[0] = Vec3(0.01, 0.02, h - d);
    for (int k = 0; k < 3; ++k) c.x[k + 1] = base[k] + Vec3(0.0, 0.0, -d);
    const double dl = d / h;
    // Expanded polynomials (the factored forms above cancel catastrophically for small delta).
    const double g = 1.5 * dl * dl - 5.0 * dl * dl * dl + 5.25 * dl * dl * dl * dl;
    const double g_prime = 3.0 * dl - 15.0 * dl * dl + 21.0 * dl * dl * dl;
    const double volume = area * h * (3.0 * dl - 3.0 * dl * dl + dl * dl * dl) / 3.0;
    const double energy = penalty * (4.0 * contactor_volume * g +
                                     4.0 / big_h * area * h * h *
                                         (dl * dl / 2 - dl * dl * dl / 3 + dl * dl * dl * dl / 12));
    const double force = penalty * (4.0 * contactor_volume * g_prime / h +
                                    4.0 / big_h * area * h * (dl - dl * dl + dl * dl * dl / 3));
    const double tol = 1e-13 + 2e-14 / dl;
    for (int order = 0; order < 2; ++order) {
      const ContactPairResult r = order == 0 ? potential_contact(c, target, penalty)
                                             : potential_contact(target, c, penalty);
      REQUIRE(r.overlapping);
      CHECK(r.overlap_volume == Approx(volume).epsilon(tol));
      CHECK(r.energy == Approx(energy).epsilon(tol));
      Vec3 resultant = Vec3::Zero();
      for (int v = 0; v < 4; ++v)
        resultant += order == 0 ? r.force_contactor[v] : r.force_target[v];
      CHECK(resultant.z() == Approx(force).epsilon(tol));
      CHECK(std::hypot(resultant.x(), resultant.y()) <= tol * force);
      if (order == 0) CHECK(r.normal.z() == Approx(1.0).epsilon(1e-12));
    }
    const ContactPairResult r = potential_contact(c, target, penalty);
    Vec3 resultant = Vec3::Zero();
    for (int v = 0; v < 4; ++v) resultant += r.force_contactor[v];
    std::printf(
        "[slab] d/h = %.2e: V = %.6e m3, U = %.6e J; relative errors V %.1e, U %.1e, "
        "F %.1e\n",
        dl, r.overlap_volume, r.energy, std::abs(r.overlap_volume / volume - 1.0),
        std::abs(r.energy / energy - 1.0), std::abs(resultant.z() / force - 1.0));
  }
}

TEST_CASE("separated and touching tets give zero, and contact starts continuously",
          "[potential_contact]") {
  // Tolerances: separated -> exactly zero; touching -> |U| <= 1e-14 p V, |f| <= 1e-13 p L^2;
  // onset: U(eps) ~ eps^2 and f(eps) ~ eps for face-face contact (ratio within 1e-3).
  const double penalty = 1.0e10;
  const TetCorners t = unit_tet();
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 rot = random_rotation(rng);
    const Vec3 shift(trial * 0.37, -1.0, 2.0);
    const TetCorners tt = transformed(t, rot, shift);
    const double volume = 1.0 / 6.0;

    // Apart along a face normal.
    TetCorners far = transformed(t, rot, shift + rot * Vec3(1.01, 0.0, 0.0));
    for (int v = 0; v < 4; ++v) far.x[v] = tt.x[v] + rot * Vec3(-1.5, -1.5, -1.5);
    ContactPairResult r = potential_contact(far, tt, penalty);
    CHECK_FALSE(r.overlapping);
    CHECK(r.energy == 0.0);
    CHECK(largest_nodal_force(r) == 0.0);
    CHECK_FALSE(tets_may_overlap(far, tt));

    // Shared face (two halves of a crack): mirror the apex through face (1,2,3).
    TetCorners mirror = tt;
    const Vec3 n = rot * Vec3(1, 1, 1).normalized();
    const double dist = n.dot(tt.x[1] - tt.x[0]);
    mirror.x[0] = tt.x[0] + 2.0 * dist * n;
    r = potential_contact(mirror, tt, penalty);
    CHECK(std::abs(r.energy) <= 1e-14 * penalty * volume);
    CHECK(largest_nodal_force(r) <= 1e-13 * penalty);
    CHECK(std::isfinite(r.energy));

    // Vertex on the middle of a face.
    TetCorners vertex_touch;
    const Vec3 face_mid = (tt.x[1] + tt.x[2] + tt.x[3]) / 3.0;
    for (int v = 0; v < 4; ++v)
      vertex_touch.x[v] = face_mid + rot * (0.5 * t.x[v] + 0.1 * Vec3(1, 1, 1));
    vertex_touch.x[0] = face_mid;
    r = potential_contact(vertex_touch, tt, penalty);
    CHECK(std::abs(r.energy) <= 1e-14 * penalty * volume);
    CHECK(largest_nodal_force(r) <= 1e-13 * penalty);

    // Onset through the shared face: mirror pushed in by eps.
    double previous_u = 0.0, previous_f = 0.0;
    for (double eps : {4e-5, 2e-5}) {
      TetCorners pushed = mirror;
      for (int v = 0; v < 4; ++v) pushed.x[v] -= eps * n;
      r = potential_contact(pushed, tt, penalty);
      REQUIRE(r.overlapping);
      if (previous_u > 0.0) {
        CHECK(r.energy / previous_u == Approx(0.25).epsilon(1e-3));
        CHECK(r.normal_force / previous_f == Approx(0.5).epsilon(1e-3));
        CHECK(r.normal.dot(n) == Approx(1.0).epsilon(1e-9));  // pushed back out
      }
      previous_u = r.energy;
      previous_f = r.normal_force;
    }
  }
}

TEST_CASE("barycentric values at the other corners, four lanes, equal value() bit for bit",
          "[potential_contact]") {
  // plane_values_at_other uses BarycentricMap::value() and prepare_tet_pair the lanes: the same
  // bits, or a pair apart at its remembered plane could be decided otherwise than by the frame.
  std::mt19937_64 rng(4711);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  int compared = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const double scale = std::pow(10.0, u(rng));  // tets of 1 mm to 1 km
    const TetCorners a = random_tet(rng, scale, Vec3(u(rng), u(rng), u(rng)) * scale, 0.3);
    const TetCorners b = random_tet(rng, scale, Vec3(u(rng), u(rng), u(rng)) * scale, 0.3);
    BarycentricMap map;
    if (!make_barycentric_map(a, tet_centroid(a), map)) continue;
    Vec3 local[4];
    for (int v = 0; v < 4; ++v) local[v] = b.x[v] - tet_centroid(a);
    double lambda[4][4];
    barycentric_at_corners(map, local, lambda);
    for (int v = 0; v < 4; ++v)
      for (int k = 0; k < 4; ++k) {
        const double expected = map.value(k, local[v]);
        CHECK(std::memcmp(&lambda[v][k], &expected, sizeof expected) == 0);
        ++compared;
      }
  }
  CHECK(compared > 30000);
}

TEST_CASE("tets_may_overlap never rejects an overlapping pair", "[potential_contact]") {
  // 20000 random pairs in a 3x3x3 box of unit-size tets; the exact kernel without rejection is
  // the reference.  Also reports how many pairs each stage would reject.
  std::mt19937_64 rng(31337);
  std::uniform_real_distribution<double> u(0.0, 1.8);
  int overlapping = 0, passed = 0, missed = 0, edge_rejected = 0, edge_wrong = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const TetCorners a = random_tet(rng, 0.5 + u(rng), Vec3(u(rng), u(rng), u(rng)), 0.3);
    const TetCorners b = random_tet(rng, 0.5 + u(rng), Vec3(u(rng), u(rng), u(rng)), 0.3);
    const bool exact = potential_contact_unculled(a, b, 1.0).overlapping;
    const bool may = tets_may_overlap(a, b);
    const bool edge = may && separated_by_edge_axis(a, b);
    overlapping += exact;
    passed += may;
    missed += exact && !may;
    edge_rejected += edge;
    edge_wrong += exact && edge;
    CHECK_FALSE((exact && !may));
    CHECK(potential_contact(a, b, 1.0).overlapping == exact);
  }
  CHECK(missed == 0);
  CHECK(edge_wrong == 0);
  std::printf(
      "[rejection] 20000 pairs: %d overlap, %d pass boxes+face planes, %d of those "
      "separated by an edge axis\n",
      overlapping, passed, edge_rejected);
}

TEST_CASE(
    "an edge-edge axis with a clear gap separates what the face planes pass and never hides an "
    "overlap",
    "[potential_contact]") {
  // A tet's top edge (slanted along x) under another's bottom edge (slanted along y), gap g along
  // their common normal: their boxes meet, no face plane separates them, the axis of the two
  // edges does.
  const auto crossing = [](double gap, Vec3(&a)[4], Vec3(&b)[4]) {
    const Vec3 up = Vec3(-2, -2, 4).normalized() * gap;
    a[0] = Vec3(-1, 0, -0.5), a[1] = Vec3(1, 0, 0.5), a[2] = Vec3(0, -1, -1), a[3] = Vec3(0, 1, -1);
    b[0] = Vec3(0, -1, -0.5) + up, b[1] = Vec3(0, 1, 0.5) + up, b[2] = Vec3(-1, 0, 1) + up,
    b[3] = Vec3(1, 0, 1) + up;
  };
  for (const double gap : {1e-2, 1e-6, 1e-13, -1e-3}) {
    Vec3 a[4], b[4];
    crossing(gap, a, b);
    TetCorners ta, tb;
    std::copy_n(a, 4, ta.x);
    std::copy_n(b, 4, tb.x);
    INFO("gap " << gap);
    CHECK(tets_may_overlap(ta, tb));
    // Above 1e-9 of the extents (2 m along z here) only: a gap of 1e-13 is left to the kernel.
    CHECK((clearly_separating_edge_axis(a, b) >= 0) == (gap > 1e-8));
    CHECK(potential_contact_unculled(ta, tb, 1.0).overlapping == (gap < 0.0));
  }
  // Random pairs: a clear edge-axis gap never hides an overlap the exact kernel finds.
  std::mt19937_64 rng(20261129);
  std::uniform_real_distribution<double> u(0.0, 1.8);
  int separated = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const TetCorners a = random_tet(rng, 0.5 + u(rng), Vec3(u(rng), u(rng), u(rng)), 0.3);
    const TetCorners b = random_tet(rng, 0.5 + u(rng), Vec3(u(rng), u(rng), u(rng)), 0.3);
    if (!tets_may_overlap(a, b) || clearly_separating_edge_axis(a.x, b.x) < 0) continue;
    ++separated;
    CHECK_FALSE(potential_contact_unculled(a, b, 1.0).overlapping);
  }
  CHECK(separated > 100);
}

TEST_CASE("2-tet impact with central differences conserves energy and momentum",
          "[potential_contact]") {
  // Two rigid tets (translation only: lumped node masses move together), no elasticity, head-on
  // at 2 m/s relative speed, generic orientations.  Central difference with dt = 0.02 / omega,
  // omega^2 = p L / m (a stiffness estimate).  Energy E = KE + U is measured with the mid-step
  // velocity average.  Tolerances: max |E - E0| <= 1e-3 E0 over the whole impact (for penalties
  // 1e8, 1e9, 1e10 Pa); total momentum constant to 1e-12 relative; the tets separate again.
  const double density = 2500.0, size = 0.1;
  std::mt19937_64 rng(77);
  for (double penalty : {1.0e8, 1.0e9, 1.0e10}) {
    TetCorners tet[2];
    tet[0] = random_tet(rng, size, Vec3(0.0, 0.0, 0.0), 0.2);
    tet[1] = random_tet(rng, size, Vec3(0.0, 0.0, 0.0), 0.2);
    double mass[2];
    for (int s = 0; s < 2; ++s) mass[s] = density * std::abs(signed_volume(tet[s]));
    // Place them just apart along x.
    double gap_shift = 0.0;
    for (;;) {
      TetCorners moved = tet[1];
      for (int v = 0; v < 4; ++v) moved.x[v].x() += gap_shift;
      if (!potential_contact_unculled(tet[0], moved, penalty).overlapping) break;
      gap_shift += 0.001 * size;
    }
    for (int v = 0; v < 4; ++v) tet[1].x[v].x() += gap_shift + 0.002 * size;
    Vec3 vel[2] = {Vec3(1.0, 0.05, 0.0), Vec3(-1.0, 0.0, -0.03)};
    const double omega = std::sqrt(penalty * size / std::min(mass[0], mass[1]));
    const double dt = 0.02 / omega;
    const Vec3 momentum0 = mass[0] * vel[0] + mass[1] * vel[1];
    const double ke0 = 0.5 * mass[0] * vel[0].squaredNorm() + 0.5 * mass[1] * vel[1].squaredNorm();
    auto force_on = [&](Vec3(&f)[2]) {
      const ContactPairResult r = potential_contact(tet[0], tet[1], penalty);
      f[0] = f[1] = Vec3::Zero();
      for (int v = 0; v < 4; ++v) {
        f[0] += r.force_contactor[v];
        f[1] += r.force_target[v];
      }
      return r;
    };
    Vec3 f[2];
    ContactPairResult r = force_on(f);
    // Half-step velocities v_{-1/2}.
    Vec3 half[2] = {vel[0] - 0.5 * dt * f[0] / mass[0], vel[1] - 0.5 * dt * f[1] / mass[1]};
    double worst = 0.0, max_energy = 0.0, worst_momentum = 0.0;
    bool touched = false, separated = false;
    int steps = 0;
    for (; steps < 2000000 && !separated; ++steps) {
      Vec3 next_half[2];
      for (int s = 0; s < 2; ++s) next_half[s] = half[s] + dt * f[s] / mass[s];
      const double ke = 0.5 * mass[0] * (0.5 * (half[0] + next_half[0])).squaredNorm() +
                        0.5 * mass[1] * (0.5 * (half[1] + next_half[1])).squaredNorm();
      worst = std::max(worst, std::abs(ke + r.energy - ke0) / ke0);
      max_energy = std::max(max_energy, r.energy);
      const Vec3 momentum = mass[0] * next_half[0] + mass[1] * next_half[1];
      worst_momentum = std::max(worst_momentum, (momentum - momentum0).norm() / momentum0.norm());
      for (int s = 0; s < 2; ++s) {
        half[s] = next_half[s];
        for (int v = 0; v < 4; ++v) tet[s].x[v] += dt * half[s];
      }
      r = force_on(f);
      touched = touched || r.overlapping;
      separated = touched && !r.overlapping &&
                  (half[1] - half[0]).dot(tet_centroid(tet[1]) - tet_centroid(tet[0])) > 0;
    }
    CHECK(touched);
    CHECK(separated);
    CHECK(max_energy > 0.5 * ke0);  // a real impact: most kinetic energy went into U
    CHECK(worst <= 1e-3);
    CHECK(worst_momentum <= 1e-12);
    std::printf(
        "[impact] p = %.0e Pa: %d steps, max U/KE0 = %.3f, max |dE|/E0 = %.2e, "
        "max |dP|/P0 = %.2e\n",
        penalty, steps, max_energy / ke0, worst, worst_momentum);
  }
}
