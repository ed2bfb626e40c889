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

// The jointed cube's scene and a plain body "lid" of the same rock.
Scene two_body_scene() {
  Scene scene = testing::jointed_scene();
  BodySpec lid = scene.bodies[0];
  lid.name = "lid";
  lid.joints = JointPlacement::none;
  scene.bodies.push_back(lid);
  return scene;
}

std::set<std::pair<LocalIndex, LocalIndex>> pairs_of(const ContactStage& stage) {
  std::set<std::pair<LocalIndex, LocalIndex>> out;
  for (const CandidatePair& p : stage.candidates()) out.emplace(p.a, p.b);
  return out;
}

void corners_of(const Model& model, LocalIndex t, Vec3 (&x)[4]) {
  for (int c = 0; c < 4; ++c) x[c] = vec3_at(model.nodes.x.data(), model.tets.nodes[4 * t + c]);
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
    const int k = 24;
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

TEST_CASE(
    "exact narrowing keeps a subset of the face-plane pairs, drops only pairs farther than "
    "the buffer, and changes no force",
    "[contact][tet_distance]") {
  // A jointed 5³-cell cube (its surface tets near each other but not sharing a node are what the
  // face planes cannot drop) and a plain block pressed 1 mm into its top, the cube shaken by
  // 0.5 % of a cell.
  BodyMesh block = testing::kuhn_cube(1, 0.3);
  for (std::size_t i = 0; i < block.coords.size(); ++i) block.coords[i] += i % 3 == 2 ? 0.499 : 0.1;
  Model model = build_model(two_body_scene(), {testing::kuhn_cube(5, 0.1), block});
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> shake(-5e-4, 5e-4);
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    if (model.pieces.body_of(model.nodes.piece[n]) == 0)
      for (int d = 0; d < 3; ++d) model.nodes.x[3 * n + d] += shake(random);
  const double buffer = 0.025;
  ContactStage exact(model, ContactSettings{buffer, true, true});
  ContactStage planes(model, ContactSettings{buffer, true, false});
  std::vector<std::pair<LocalIndex, LocalIndex>> bonds;
  for (LocalIndex j = 0; j < model.joints.size(); ++j)
    bonds.emplace_back(model.joints.tets[2 * j], model.joints.tets[2 * j + 1]);
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
