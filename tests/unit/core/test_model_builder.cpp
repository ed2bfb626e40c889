// Model assembly: pieces, ordering, ids, masses, the canonical force-gather map.
#include <catch2/catch.hpp>
#include <random>
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
  // gids are a permutation; forces are added in ascending tet gid
  std::set<GlobalId> ids(model.nodes.gid.begin(), model.nodes.gid.end());
  CHECK(ids.size() == 9);
  REQUIRE(model.tet_force_order.size() == 3);
  for (std::size_t k = 1; k < model.tet_force_order.size(); ++k)
    CHECK(model.tets.gid[model.tet_force_order[k - 1]] < model.tets.gid[model.tet_force_order[k]]);
  CHECK(linear_momentum(model.nodes).isApprox(mass * Vec3(1, 2, 3)));
}

TEST_CASE("build_model: a body without a material (a scene made in code) is refused, named",
          "[model]") {
  for (const int material : {-1, 1}) {
    Scene scene = scene_for(1);
    scene.bodies[0].material = material;
    CHECK_THROWS_WITH(
        build_model(scene, {two_pieces()}),
        Catch::Matchers::Contains("body '") &&
            Catch::Matchers::Contains("has material index " + std::to_string(material) +
                                      ", not one of the scene's 1 materials"));
  }
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
  for (Model* m : {&a, &b}) {
    for (LocalIndex n = 0; n < m->nodes.size(); ++n) {
      const Vec3 X = m->nodes.x0(n);
      vec3_at(m->nodes.x.data(), n) = X + 0.01 * Vec3(X.y() * X.z(), X.x() * X.x(), -X.y());
    }
    compute_internal_forces(*m);
  }
  for (LocalIndex i = 0; i < a.nodes.size(); ++i)
    for (LocalIndex j = 0; j < b.nodes.size(); ++j)
      if (a.nodes.x0(i) == b.nodes.x0(j))
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

TEST_CASE("morton keys of a long thin wall cut its length before its thickness", "[model]") {
  // A wall 8 m long (x), 0.5 m thick (y), 2 m high (z): y has 4 bits fewer, z 2 fewer.
  const Vec3 lo(0, 0, 0), hi(8, 0.5, 2);
  // The whole thickness at one end comes before the far half of the length...
  CHECK(morton_key(Vec3(3.9, 0.5, 1.9), lo, hi) < morton_key(Vec3(4.1, 0, 0), lo, hi));
  // ...and so does the whole height of the first quarter before the second quarter.
  CHECK(morton_key(Vec3(1.9, 0.5, 2), lo, hi) < morton_key(Vec3(2.1, 0, 0), lo, hi));
  // Cells about cubes below that: a step through the thickness is a low-order change.
  CHECK(morton_key(Vec3(0, 0.5, 0), lo, hi) < morton_key(Vec3(0.6, 0, 0), lo, hi));
  // The far corner has every kept bit set: 21 on x, 17 on y, 19 on z.
  const std::uint64_t corner = morton_key(Vec3(8, 0.5, 2), lo, hi);
  for (int level = 0; level < 21; ++level) {
    CHECK(((corner >> (3 * level)) & 1u) == 1u);
    CHECK(((corner >> (3 * level + 1)) & 1u) == (level < 17 ? 1u : 0u));
    CHECK(((corner >> (3 * level + 2)) & 1u) == (level < 19 ? 1u : 0u));
  }
}

TEST_CASE("nodal forces are bit-identical whatever the local order of the tets", "[model]") {
  // The same tets (same gids) stored in reversed local order give the same bits: forces are added
  // in ascending gid, not in storage order (the basis of rank-invariant results).
  Scene scene = scene_for(1);
  BodyMesh mesh;
  mesh.source = "test";
  for (int k = 0; k < 3; ++k)  // a 2x1x1 strip of Kuhn-like tets sharing nodes
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i)
        mesh.coords.insert(mesh.coords.end(), {double(i), double(j), double(k)});
  auto id = [](int i, int j, int k) { return static_cast<LocalIndex>((k * 2 + j) * 3 + i); };
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < 2; ++i) {
      mesh.tets.insert(mesh.tets.end(),
                       {id(i, 0, k), id(i + 1, 0, k), id(i, 1, k), id(i, 0, k + 1)});
      mesh.tets.insert(mesh.tets.end(),
                       {id(i + 1, 0, k), id(i + 1, 1, k), id(i, 1, k), id(i + 1, 0, k + 1)});
    }
  Model a = build_model(scene, {mesh});
  Model b = a;
  TetArrays& t = b.tets;
  const LocalIndex n = t.size();
  TetArrays reversed = t;
  for (LocalIndex i = 0; i < n; ++i) {
    const LocalIndex j = n - 1 - i;
    reversed.gid[i] = t.gid[j];
    for (int c = 0; c < 4; ++c) reversed.nodes[4 * i + c] = t.nodes[4 * j + c];
    for (int c = 0; c < 9; ++c) reversed.dm_inv[9 * i + c] = t.dm_inv[9 * j + c];
    reversed.volume0[i] = t.volume0[j];
    reversed.material[i] = t.material[j];
    reversed.piece[i] = t.piece[j];
    reversed.viscosity[i] = t.viscosity[j];
  }
  b.tets = reversed;
  build_tet_force_order(b.tets, b.tet_force_order);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  for (std::size_t i = 0; i < a.nodes.x.size(); ++i)
    a.nodes.x[i] = b.nodes.x[i] = a.nodes.x0(i / 3)[i % 3] + u(rng);
  compute_internal_forces(a);
  compute_internal_forces(b);
  double largest = 0;
  for (double f : a.nodes.f) largest = std::max(largest, std::abs(f));
  CHECK(largest > 0);
  CHECK(a.nodes.f == b.nodes.f);  // bit for bit
}

TEST_CASE("build_model: a gid offset shifts every gid and changes nothing else", "[model]") {
  // A jointed body (joints: all) so that node, tet and joint gids all move.
  Scene scene = scene_for(1);
  FractureSpec fracture;
  fracture.tensile_strength = 1e6;
  fracture.cohesion = 2e6;
  fracture.friction_angle_deg = 30.0;
  fracture.energy_I = 10.0;
  fracture.energy_II = 50.0;
  scene.materials[0].fracture = fracture;
  scene.bodies[0].joints = JointPlacement::all;
  const Model plain = build_model(scene, {two_pieces()});
  REQUIRE(plain.joints.size() == 1);  // the face shared by the second piece's two tets
  for (GlobalId offset : {(GlobalId{1} << 32) + 12345, (GlobalId{1} << 62) - 1000}) {
    scene.parallel.gid_offset = offset;
    const Model shifted = build_model(scene, {two_pieces()});
    CHECK(shifted.gid_offset == offset);
    const auto plus = [&](std::vector<GlobalId> gids) {
      for (GlobalId& g : gids) g += offset;
      return gids;
    };
    CHECK(shifted.nodes.gid == plus(plain.nodes.gid));
    CHECK(shifted.tets.gid == plus(plain.tets.gid));
    CHECK(shifted.joints.gid == plus(plain.joints.gid));
    CHECK(shifted.nodes.reference == plain.nodes.reference);
    CHECK(shifted.nodes.reference_positions == plain.nodes.reference_positions);
    CHECK(shifted.nodes.mass == plain.nodes.mass);
    CHECK(shifted.tets.nodes == plain.tets.nodes);
    CHECK(shifted.tets.contact_group == plain.tets.contact_group);
    CHECK(shifted.joints.nodes == plain.joints.nodes);
    CHECK(shifted.joints.tets == plain.joints.tets);
    CHECK(shifted.tet_force_order == plain.tet_force_order);
  }
}

TEST_CASE("local_count refuses more entries than one rank can index", "[model]") {
  CHECK(local_count(0, "nodes") == 0);
  CHECK(local_count(static_cast<std::size_t>(max_local_entries), "tetrahedra") ==
        max_local_entries);
  // 9 values per tet (Dm⁻¹) must stay addressable by a 32-bit index.
  CHECK(9 * static_cast<std::int64_t>(max_local_entries) <= 0x7fffffff);
  CHECK_THROWS_WITH(local_count(static_cast<std::size_t>(max_local_entries) + 1, "tetrahedra"),
                    Catch::Contains("238609295 tetrahedra") && Catch::Contains("more ranks"));
  CHECK_THROWS_AS(local_count(std::size_t{1} << 33, "nodes"), InputError);
}

TEST_CASE("prescribed velocities are stored only when a load moves nodes", "[model]") {
  // Fixed bodies alone: held at rest without the array (24 bytes per node saved).
  Scene scene = scene_for(2);
  scene.bodies[0].fixed = true;
  const Model held = build_model(scene, {two_pieces(), two_pieces()});
  CHECK_FALSE(held.nodes.has_prescribed_velocity);
  CHECK(held.nodes.prescribed_velocity.empty());
  CHECK(held.nodes.constrained[0] == 7);
  CHECK(held.nodes.prescribed_velocity_at(0) == 0.0);

  // A velocity load on body 1: the array is there and holds the load's velocity.
  LoadSpec load;
  load.kind = LoadSpec::Kind::velocity;
  load.bodies = {1};
  load.velocity = Vec3(0, 0, -0.5);
  scene.loads.push_back(load);
  const Model moved = build_model(scene, {two_pieces(), two_pieces()});
  CHECK(moved.nodes.has_prescribed_velocity);
  REQUIRE(moved.nodes.prescribed_velocity.size() ==
          3 * static_cast<std::size_t>(moved.nodes.size()));
  int driven = 0;
  for (LocalIndex n = 0; n < moved.nodes.size(); ++n)
    if (moved.pieces.body_of(moved.nodes.piece[n]) == 1) {
      ++driven;
      CHECK(moved.nodes.prescribed_velocity_at(3 * n + 2) == -0.5);
    }
  CHECK(driven == 9);
}
