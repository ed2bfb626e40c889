// Exact tet–tet distance (contact/tet_distance.hpp) against closed forms and a sampled bound, and
// the contact stage's narrowing by it: a subset of the face-plane narrowing's pairs, every pair it
// drops farther apart than the buffer, the same forces bit for bit.
#include <algorithm>
#include <catch2/catch.hpp>
#include <random>
#include <set>

#include "contact/contact_stage.hpp"
#include "contact/tet_distance.hpp"
#include "core/model_builder.hpp"
#include "jointed_cube.hpp"

using namespace fdem;
using fdem::testing::pairs_of;

namespace {

using Corners = Vec3[4];

void copy_tet(const Vec3 (&from)[4], const Vec3& shift, double scale, Vec3 (&to)[4]) {
  for (int c = 0; c < 4; ++c) to[c] = scale * from[c] + shift;
}

// Smallest distance between points of a barycentric grid (k subdivisions) on each tet: an upper
// bound of the true distance, within the grid spacing of it.
double sampled_distance(const Vec3 (&a)[4], const Vec3 (&b)[4], int k) {
  std::vector<Vec3> pa, pb;
  for (int i = 0; i <= k; ++i)
    for (int j = 0; i + j <= k; ++j)
      for (int l = 0; i + j + l <= k; ++l) {
        const double w[4] = {double(i) / k, double(j) / k, double(l) / k,
                             double(k - i - j - l) / k};
        Vec3 p = Vec3::Zero(), q = Vec3::Zero();
        for (int c = 0; c < 4; ++c) {
          p += w[c] * a[c];
          q += w[c] * b[c];
        }
        pa.push_back(p);
        pb.push_back(q);
      }
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& p : pa)
    for (const Vec3& q : pb) best = std::min(best, (p - q).squaredNorm());
  return std::sqrt(best);
}

void corners_of(const Model& model, LocalIndex t, Vec3 (&x)[4]) {
  for (int c = 0; c < 4; ++c) x[c] = vec3_at(model.nodes.x.data(), model.tets.nodes[4 * t + c]);
}

// Whether p lies inside the tet, off its faces: the four sub-tets p forms with the faces have
// the orientation of the tet.
bool strictly_inside(const Vec3 (&x)[4], const Vec3& p) {
  const auto volume = [](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    return (b - a).cross(c - a).dot(d - a);
  };
  const double whole = volume(x[0], x[1], x[2], x[3]);
  const double parts[4] = {volume(p, x[1], x[2], x[3]), volume(x[0], p, x[2], x[3]),
                           volume(x[0], x[1], p, x[3]), volume(x[0], x[1], x[2], p)};
  for (double part : parts)
    if (!(part * whole > 0.0)) return false;
  return true;
}

}  // namespace

TEST_CASE("tet distance: closed forms for face, edge and corner gaps, 0 when touching or inside",
          "[contact][tet_distance]") {
  const Corners unit = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  Corners other;
  // Face x + y + z = 1 against the tet mirrored through its centroid, moved off along (1,1,1).
  const double gap = 0.3;
  for (int c = 0; c < 4; ++c)
    other[c] = Vec3(1.0 / 3, 1.0 / 3, 1.0 / 3) * 2 - unit[c] + gap / std::sqrt(3.0) * Vec3::Ones();
  CHECK(tet_distance(unit, other) == Approx(gap).epsilon(1e-12));
  // Crossed edges: edge (0,0,0)–(1,0,0) of the unit tet and a tet whose edge runs along y at
  // x = 0.5, z = −0.2, its other corners below: distance 0.2 between the two edges.
  const Corners below = {Vec3(0.5, -1, -0.2), Vec3(0.5, 1, -0.2), Vec3(0, 0, -2), Vec3(1, 0, -2)};
  CHECK(tet_distance(unit, below) == Approx(0.2).epsilon(1e-12));
  // Corner to corner along x.
  copy_tet(unit, Vec3(-1.5, 0, 0), 1.0, other);  // corner (−0.5,0,0) against (0,0,0)
  CHECK(tet_distance(unit, other) == Approx(0.5).epsilon(1e-12));
  CHECK(tet_distance(other, unit) == Approx(0.5).epsilon(1e-12));
  // Touching at a corner, sharing a face, one inside the other: 0.
  copy_tet(unit, Vec3(-1, 0, 0), 1.0, other);
  CHECK(tet_distance(unit, other) == 0.0);
  copy_tet(unit, Vec3(0.1, 0.1, 0.1), 0.2, other);
  CHECK(tet_distance(unit, other) == 0.0);
  CHECK(tet_distance(other, unit) == 0.0);
  CHECK(tet_distance(unit, unit) == 0.0);
}

TEST_CASE("tet distance: random pairs lie between the sampled bound less its spacing and it",
          "[contact][tet_distance]") {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int apart = 0, intersecting = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Corners a, b;
    for (int c = 0; c < 4; ++c) {
      a[c] = Vec3(u(random), u(random), u(random));
      b[c] = Vec3(u(random), u(random), u(random)) + Vec3(0.8 * u(random), 0.8 * u(random), 1.0);
    }
    const int k = 12;  // 455 points per tet: seconds under the sanitizers
    const double d = tet_distance(a, b), sampled = sampled_distance(a, b, k);
    double longest = 0.0;  // the grid's spacing is at most the longest edge / k on each tet
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        longest = std::max({longest, (a[i] - a[j]).norm(), (b[i] - b[j]).norm()});
    INFO("trial " << trial << ": distance " << d << ", sampled " << sampled);
    CHECK(d <= sampled + 1e-12);
    CHECK(d >= sampled - 2.0 * longest / k);
    (d > 0.0 ? apart : intersecting) += 1;
  }
  CHECK(apart > 50);
  CHECK(intersecting > 50);
}

TEST_CASE("tets within a distance: the early-exit test agrees with the exact distance",
          "[contact][tet_distance]") {
  // Random pairs from apart to nested (a small tet inside a large one: every corner–face and
  // edge–edge distance exceeds the reach, only the separating-axis test keeps it), each asked at
  // reaches just below and just above its distance and at 0 and a large reach.
  std::mt19937_64 random(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int apart = 0, intersecting = 0, nested = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    Corners a, b;
    for (int c = 0; c < 4; ++c) a[c] = 2.0 * Vec3(u(random), u(random), u(random));
    const bool small = trial % 4 == 0;  // every 4th pair: b a small tet near a's centroid
    const Vec3 centre =
        small ? 0.25 * (a[0] + a[1] + a[2] + a[3]) + 0.1 * Vec3(u(random), u(random), u(random))
              : Vec3(0.6 * u(random), 0.6 * u(random), 2.5 * u(random));
    for (int c = 0; c < 4; ++c)
      b[c] = centre + (small ? 0.05 : 1.0) * Vec3(u(random), u(random), u(random));
    const double d = tet_distance(a, b);
    INFO("trial " << trial << ": distance " << d);
    if (d > 0.0) {
      ++apart;
      CHECK_FALSE(tets_within(a, b, 0.999 * d));
      CHECK(tets_within(a, b, 1.001 * d));
      CHECK_FALSE(tets_within(b, a, 0.999 * d));
    } else {
      ++intersecting;
      CHECK(tets_within(a, b, 0.0));
      CHECK(tets_within(b, a, 0.0));
      bool b_inside_a = true;  // then at reach 0 only the separating-axis test can keep it
      for (int c = 0; c < 4; ++c) b_inside_a = b_inside_a && strictly_inside(a, b[c]);
      nested += b_inside_a;
    }
    CHECK(tets_within(a, b, 10.0));
  }
  CHECK(apart > 200);
  CHECK(intersecting > 200);
  CHECK(nested > 20);
}

TEST_CASE(
    "exact narrowing keeps a subset of the face-plane pairs, drops only pairs farther than "
    "the buffer, and changes no force",
    "[contact][tet_distance]") {
  // A jointed 5³-cell cube (its surface tets near each other but not sharing a node are what the
  // face planes cannot drop) and a plain block pressed 1 mm into its top, the cube shaken by
  // 0.5 % of a cell.
  Model model = testing::pressed_jointed_cube();
  const double buffer = 0.025;
  ContactStage exact(model, ContactSettings{buffer, true, true});
  ContactStage planes(model, ContactSettings{buffer, true, false});
  const auto bonds = testing::joint_bonds(model);
  for (ContactStage* stage : {&exact, &planes}) {
    stage->set_bonds(model.tets.size(), bonds);
    stage->enclose(model.tets.enclosed);
    stage->detect(model);
  }
  const auto kept = pairs_of(exact), before = pairs_of(planes);
  CHECK(std::includes(before.begin(), before.end(), kept.begin(), kept.end()));
  INFO("face planes " << before.size() << " pairs, exact " << kept.size());
  CHECK(kept.size() < before.size() / 2);
  for (const auto& [a, b] : before) {
    if (kept.count({a, b})) continue;
    Vec3 xa[4], xb[4];
    corners_of(model, a, xa);
    corners_of(model, b, xb);
    CHECK(tet_distance(xa, xb) > buffer);
  }
  model.nodes.f.assign(model.nodes.x.size(), 0.0);
  const ContactForceSummary s_planes = planes.add_forces(model, 1e-6);
  const std::vector<double> f_planes = model.nodes.f;
  model.nodes.f.assign(model.nodes.x.size(), 0.0);
  const ContactForceSummary s_exact = exact.add_forces(model, 1e-6);
  CHECK(s_planes.active_pairs > 0);
  CHECK(s_exact.active_pairs == s_planes.active_pairs);
  CHECK(s_exact.energy == s_planes.energy);
  CHECK(model.nodes.f == f_planes);
}
