// Model assembly: pieces, ordering, ids, masses, the canonical force-gather map.
#include <catch2/catch.hpp>
#include <set>

#include "core/dynamics.hpp"
#include "core/error.hpp"
#include "core/model_builder.hpp"

using namespace fdem;

namespace {

// Two unit tets sharing nothing, plus a cube-like pair sharing a face.
BodyMesh two_pieces() {
  BodyMesh m;
  m.source = "test";
  m.coords = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 5, 0, 0, 6, 0, 0, 5, 1, 0, 5, 0, 1, 6, 1, 1};
  m.tets = {0, 1, 2, 3, 4, 5, 6, 7, 5, 8, 6, 7};
  // second piece: tets (4,5,6,7) and (5,8,6,7) share face 5-6-7
  return m;
}

Scene scene_for(int bodies) {
  Scene s;
  s.source_path = "test.yaml";
  MaterialSpec m;
  m.name = "rock";
  m.density = 2000;
  m.elastic.young = 1e9;
  m.elastic.poisson = 0.2;
  s.materials.push_back(m);
  for (int b = 0; b < bodies; ++b) {
    BodySpec body;
    body.name = "b" + std::to_string(b);
    body.material = 0;
    s.bodies.push_back(body);
  }
  return s;
}

}  // namespace

TEST_CASE("connected pieces of a mesh", "[model]") {
  const BodyMesh m = two_pieces();
  std::int32_t n = 0;
  const auto piece = connected_pieces(m.tets, 9, &n);
  CHECK(n == 2);
  CHECK(piece[0] != piece[1]);
  CHECK(piece[1] == piece[2]);
}

TEST_CASE("build_model: masses, pieces, ids and gather map", "[model]") {
  Scene scene = scene_for(1);
  scene.bodies[0].velocity = Vec3(1, 2, 3);
  const Model model = build_model(scene, {two_pieces()});
  CHECK(model.pieces.size() == 2);
  CHECK(model.tets.size() == 3);
  CHECK(model.nodes.size() == 9);
  double mass = 0;
  for (double m : model.nodes.mass) mass += m;
  CHECK(mass == Approx(2000.0 * (1.0 / 6 + 1.0 / 6 + 1.0 / 3)).epsilon(1e-14));
  // gids are a permutation, rows of the gather map are sorted by tet gid
  std::set<GlobalId> ids(model.nodes.gid.begin(), model.nodes.gid.end());
  CHECK(ids.size() == 9);
  for (LocalIndex n = 0; n < model.nodes.size(); ++n)
    for (LocalIndex s = model.node_corners.offsets[n] + 1; s < model.node_corners.offsets[n + 1];
         ++s)
      CHECK(model.tets.gid[model.node_corners.slots[s - 1] / 4] <
            model.tets.gid[model.node_corners.slots[s] / 4]);
  CHECK(linear_momentum(model.nodes).isApprox(mass * Vec3(1, 2, 3)));
}

TEST_CASE("inverted tetrahedra are rejected with the element named", "[model]") {
  BodyMesh m = two_pieces();
  std::swap(m.tets[1], m.tets[2]);
  m.source_tags = {101, 102, 103};
  try {
    build_model(scene_for(1), {m});
    FAIL("no error");
  } catch (const InputError& e) {
    const std::string msg = e.what();
    CHECK_THAT(msg, Catch::Contains("tetrahedron 101"));
    CHECK_THAT(msg, Catch::Contains("inverted"));
    CHECK_THAT(msg, Catch::Contains("b0"));
  }
}

TEST_CASE("element order does not change the physics", "[model]") {
  // The same mesh in two element orders, deformed alike: nodal forces agree node by node.
  const Scene scene = scene_for(1);
  Model a = build_model(scene, {two_pieces()}, ElementOrder::space_filling_curve);
  Model b = build_model(scene, {two_pieces()}, ElementOrder::as_given);
  REQUIRE(a.tets.size() == b.tets.size());
  std::vector<double> corners;
  for (Model* m : {&a, &b}) {
    for (LocalIndex n = 0; n < m->nodes.size(); ++n) {
      const Vec3 X = vec3_at(m->nodes.x0.data(), n);
      vec3_at(m->nodes.x.data(), n) = X + 0.01 * Vec3(X.y() * X.z(), X.x() * X.x(), -X.y());
    }
    compute_internal_forces(*m, corners);
    gather_corner_forces(m->node_corners, corners, m->nodes.f);
  }
  for (LocalIndex i = 0; i < a.nodes.size(); ++i)
    for (LocalIndex j = 0; j < b.nodes.size(); ++j)
      if (vec3_at(a.nodes.x0.data(), i) == vec3_at(b.nodes.x0.data(), j))
        CHECK((vec3_at(a.nodes.f.data(), i) - vec3_at(b.nodes.f.data(), j)).norm() <=
              1e-12 * (1.0 + vec3_at(a.nodes.f.data(), i).norm()));
}

TEST_CASE("morton keys preserve locality along each axis", "[model]") {
  const Vec3 lo(0, 0, 0), hi(1, 1, 1);
  CHECK(morton_key(Vec3(0, 0, 0), lo, hi) == 0);
  CHECK(morton_key(Vec3(1, 0, 0), lo, hi) < morton_key(Vec3(0, 1, 0), lo, hi));
  CHECK(morton_key(Vec3(0, 1, 0), lo, hi) < morton_key(Vec3(0, 0, 1), lo, hi));
  CHECK(morton_key(Vec3(1, 1, 1), lo, hi) == 0x7fffffffffffffffULL);
}
