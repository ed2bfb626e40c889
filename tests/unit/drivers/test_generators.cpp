// Scene generators (wall, arch, tower): piece counts, exact volumes, orientation, conforming
// faces between touching units (joints: interfaces), running-bond offsets, and the reader's keys
// and messages for them.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "core/model_builder.hpp"
#include "core/tet_kernels.hpp"
#include "drivers/mesh_generators.hpp"
#include "drivers/scene_builders.hpp"
#include "io/scene_reader.hpp"

using namespace fdem;
using Catch::Matchers::Contains;

namespace {

struct PieceBox {
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  double volume = 0;
};

struct MeshFacts {
  std::int32_t pieces = 0;
  double volume = 0, min_volume = 1e300;
  std::vector<PieceBox> boxes;  // per piece, in piece order
};

MeshFacts facts(const BodyMesh& mesh) {
  MeshFacts f;
  const auto piece =
      connected_pieces(mesh.tets, static_cast<LocalIndex>(mesh.coords.size() / 3), &f.pieces);
  f.boxes.resize(f.pieces);
  for (std::size_t t = 0; t < mesh.tets.size() / 4; ++t) {
    Vec3 X[4];
    for (int c = 0; c < 4; ++c) X[c] = vec3_at(mesh.coords.data(), mesh.tets[4 * t + c]);
    const double v = tet_reference(X).volume;
    f.volume += v;
    f.min_volume = std::min(f.min_volume, v);
    PieceBox& b = f.boxes[piece[t]];
    b.volume += v;
    for (const Vec3& x : X) {
      b.lo = b.lo.cwiseMin(x);
      b.hi = b.hi.cwiseMax(x);
    }
  }
  return f;
}

MaterialSpec mortar_material() {
  MaterialSpec m;
  m.name = "brick";
  m.density = 1800;
  m.elastic.young = 5e9;
  m.elastic.poisson = 0.2;
  m.fracture = builders::fracture_spec(0.2e6, 0.3e6, 35.0);
  return m;
}

// Joints that `joints: interfaces` places on a generated body.
LocalIndex interface_joints(const MeshSpec& mesh) {
  Scene scene;
  scene.source_path = "test";
  scene.time.end = 1;
  scene.materials.push_back(mortar_material());
  BodySpec body;
  body.name = "masonry";
  body.material = 0;
  body.mesh = mesh;
  body.joints = JointPlacement::interfaces;
  scene.bodies.push_back(body);
  const Model model = build_model(scene, load_body_meshes(scene));
  // Every joint joins two different pieces and two coincident triangles.
  for (LocalIndex j = 0; j < model.joints.size(); ++j) {
    REQUIRE(model.tets.piece[model.joints.tets[2 * j]] !=
            model.tets.piece[model.joints.tets[2 * j + 1]]);
    for (int i = 0; i < 3; ++i)
      REQUIRE((model.nodes.x0(model.joints.nodes[6 * j + i]) -
               model.nodes.x0(model.joints.nodes[6 * j + 3 + i]))
                  .norm() < 1e-12);
  }
  return model.joints.size();
}

std::string input_error(const std::string& text) {
  try {
    parse_scene(text, "scene.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const char* scene_head =
    "time: {end: 0.1}\n"
    "materials:\n"
    "  brick:\n"
    "    density: 1800\n"
    "    elastic: {young: 5.0e9, poisson: 0.2}\n"
    "bodies:\n"
    "  - name: masonry\n"
    "    material: brick\n";

}  // namespace

TEST_CASE("stack-bond wall: one piece per unit, exact volume, conforming head and bed joints",
          "[drivers][generators]") {
  WallMeshSpec w;
  w.unit = Vec3(0.2, 0.1, 0.05);
  w.courses = 3;
  w.units_per_course = 4;
  w.cells[0] = 2;
  w.cells[1] = 2;
  w.cells[2] = 1;
  w.origin = Vec3(1, 2, 3);
  const MeshFacts f = facts(wall_mesh(w));
  CHECK(f.pieces == 12);
  CHECK(f.volume == Approx(12 * 0.2 * 0.1 * 0.05).epsilon(1e-12));
  CHECK(f.min_volume > 0);
  for (const PieceBox& b : f.boxes) {
    CHECK((b.hi - b.lo - w.unit).norm() < 1e-12);
    CHECK(b.volume == Approx(0.2 * 0.1 * 0.05).epsilon(1e-12));
  }
  CHECK((f.boxes[0].lo - w.origin).norm() < 1e-12);
  MeshSpec mesh;
  mesh.kind = MeshSpec::Kind::wall;
  mesh.wall = w;
  // Head joints: 3 per course × 3 courses, 2×1 cells × 2 triangles; bed joints: 2 × 4 units,
  // 2×2 cells × 2 triangles.
  CHECK(interface_joints(mesh) == 3 * 3 * 4 + 2 * 4 * 8);
}

TEST_CASE("running-bond wall: half units at the ends of alternate courses, joints offset by half",
          "[drivers][generators]") {
  WallMeshSpec w;
  w.bond = WallMeshSpec::Bond::running;
  w.unit = Vec3(0.24, 0.115, 0.07);
  w.courses = 4;
  w.units_per_course = 5;
  w.cells[0] = 4;
  w.cells[1] = 1;
  w.cells[2] = 1;
  const MeshFacts f = facts(wall_mesh(w));
  CHECK(f.pieces == 2 * 5 + 2 * 6);
  const double length = 5 * 0.24;
  CHECK(f.volume == Approx(4 * length * 0.115 * 0.07).epsilon(1e-12));
  CHECK(f.min_volume > 0);
  // Course 1 (second): half, 4 full, half; starts of the head joints shifted by half a unit.
  std::vector<double> starts, lengths;
  for (const PieceBox& b : f.boxes)
    if (std::abs(b.lo.z() - 0.07) < 1e-12) {
      starts.push_back(b.lo.x());
      lengths.push_back(b.hi.x() - b.lo.x());
    }
  std::vector<std::size_t> order(starts.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return starts[a] < starts[b]; });
  REQUIRE(order.size() == 6);
  CHECK(lengths[order[0]] == Approx(0.12));
  CHECK(lengths[order[5]] == Approx(0.12));
  for (int i = 1; i <= 4; ++i) {
    CHECK(lengths[order[i]] == Approx(0.24));
    CHECK(starts[order[i]] == Approx(0.12 + (i - 1) * 0.24));
  }
  CHECK(starts[order[5]] + lengths[order[5]] == Approx(length));
  MeshSpec mesh;
  mesh.kind = MeshSpec::Kind::wall;
  mesh.wall = w;
  // Head joints: 4 (full courses) + 5 (half courses) per pair of courses, 1×1 cells; bed joints:
  // 3 × the wall length (20 cells), 2 triangles per cell.
  CHECK(interface_joints(mesh) == 2 * (4 + 5) * 2 + 3 * 20 * 2);
}

TEST_CASE("a mortar gap separates the units, joints: interfaces then has nothing to bond",
          "[drivers][generators]") {
  WallMeshSpec w;
  w.bond = WallMeshSpec::Bond::running;
  w.unit = Vec3(0.2, 0.1, 0.05);
  w.courses = 2;
  w.units_per_course = 3;
  w.mortar_gap = 0.01;
  const MeshFacts f = facts(wall_mesh(w));
  CHECK(f.pieces == 3 + 4);
  // Length n·lx + (n − 1)·g on both courses; half units (lx − g)/2.
  double hi = 0;
  for (const PieceBox& b : f.boxes) hi = std::max(hi, b.hi.x());
  CHECK(hi == Approx(3 * 0.2 + 2 * 0.01));
  CHECK(f.volume == Approx(2 * (3 * 0.2) * 0.1 * 0.05 - 0.01 * 0.1 * 0.05).epsilon(1e-12));
  MeshSpec mesh;
  mesh.kind = MeshSpec::Kind::wall;
  mesh.wall = w;
  CHECK_THROWS_WITH(interface_joints(mesh), Contains("no two of its pieces share a triangle"));
}

TEST_CASE("arches: voussoirs as curved wedges, exact polyhedral volume, radial joints conform",
          "[drivers][generators]") {
  const double R = 2.0, t = 0.3, d = 0.5;
  for (bool segmental : {false, true}) {
    ArchMeshSpec a;
    a.radius = R;
    a.thickness = t;
    a.depth = d;
    a.voussoirs = 9;
    a.cells[0] = 2;
    a.cells[1] = 2;
    a.cells[2] = 1;
    a.origin = Vec3(1, 0, 0);
    const double rise = 0.8;
    if (segmental) {
      a.kind = ArchMeshSpec::Kind::segmental;
      a.half_angle = std::acos(1 - rise / R);
    }
    const BodyMesh mesh = arch_mesh(a);
    const MeshFacts f = facts(mesh);
    CHECK(f.pieces == 9);
    CHECK(f.min_volume > 0);
    // Chords of 18 arc cells: ring area (18/2)·((R+t)² − R²)·sin(2α/18).
    const double cell_angle = 2 * a.half_angle / 18;
    const double ring = 9 * ((R + t) * (R + t) - R * R) * std::sin(cell_angle);
    CHECK(f.volume == Approx(ring * d).epsilon(1e-12));
    // Springing of the intrados at R·cos α above the centre; the crown of the extrados at R + t.
    double z_lo = 1e300, z_hi = -1e300, x_hi = -1e300;
    for (const PieceBox& b : f.boxes) {
      z_lo = std::min(z_lo, b.lo.z());
      z_hi = std::max(z_hi, b.hi.z());
      x_hi = std::max(x_hi, b.hi.x());
    }
    CHECK(z_lo == Approx(segmental ? R - rise : 0.0).margin(1e-12));
    CHECK(z_hi == Approx(R + t).margin(1e-12));  // odd count: a voussoir is centred on the crown
    CHECK(x_hi == Approx(1 + (R + t) * std::sin(a.half_angle)));
    MeshSpec spec;
    spec.kind = MeshSpec::Kind::arch;
    spec.arch = a;
    CHECK(interface_joints(spec) == 8 * 2 * 1 * 2);  // 8 radial joints of 2×1 cells
    // Abutments: two more pieces; their tops are the springing faces (bonded too).
    spec.arch.abutments = true;
    spec.arch.abutment_width = 0.5;
    spec.arch.abutment_height = 0.6;
    const MeshFacts g = facts(arch_mesh(spec.arch));
    CHECK(g.pieces == 11);
    CHECK(g.min_volume > 0);
    // Each abutment: quadrilateral (foot 0.5, top = springing face) extruded by d.
    const double c = std::cos(0.5 * M_PI - a.half_angle), s = std::sin(0.5 * M_PI - a.half_angle);
    const Eigen::Vector2d q[4] = {{R * c, R * s - 0.6},
                                  {R * c + 0.5, R * s - 0.6},
                                  {(R + t) * c, (R + t) * s},
                                  {R * c, R * s}};
    double area = 0;
    for (int i = 0; i < 4; ++i)
      area += 0.5 * (q[i].x() * q[(i + 1) % 4].y() - q[(i + 1) % 4].x() * q[i].y());
    CHECK(g.volume == Approx(ring * d + 2 * area * d).epsilon(1e-12));
    CHECK(interface_joints(spec) == (8 + 2) * 2 * 1 * 2);
  }
}

TEST_CASE("tower: stacked blocks, one piece each, bonded faces between them",
          "[drivers][generators]") {
  TowerMeshSpec t;
  t.block = Vec3(0.3, 0.2, 0.4);
  t.blocks = 5;
  t.origin = Vec3(0, 0, 1);
  const MeshFacts f = facts(tower_mesh(t));
  CHECK(f.pieces == 5);
  CHECK(f.volume == Approx(5 * 0.3 * 0.2 * 0.4).epsilon(1e-12));
  CHECK(f.min_volume > 0);
  CHECK(f.boxes[4].hi.z() == Approx(1 + 5 * 0.4));
  MeshSpec spec;
  spec.kind = MeshSpec::Kind::tower;
  spec.tower = t;
  CHECK(interface_joints(spec) == 4 * 2 * 2 * 2);  // default 2×2×2 cells
}

TEST_CASE("scene reader: wall, arch and tower keys and their messages", "[drivers][generators]") {
  const Scene s = parse_scene(std::string(scene_head) +
                                  "    mesh: {wall: {unit: [0.2, 0.1, 0.05], courses: 3, length: "
                                  "1.0, bond: running, cells_per_unit: [4, 1, 2], origin: [0, 1, "
                                  "2]}}\n"
                                  "  - name: arch\n"
                                  "    material: brick\n"
                                  "    mesh: {arch: {kind: segmental, radius: 2, thickness: 0.3, "
                                  "depth: 0.5, voussoirs: 7, angle: 120, abutments: {width: 0.4, "
                                  "height: 0.5}}}\n"
                                  "  - name: tower\n"
                                  "    material: brick\n"
                                  "    mesh: {tower: {block: [0.3, 0.3, 0.3], blocks: 6}}\n",
                              "scene.yaml");
  REQUIRE(s.bodies.size() == 3);
  const WallMeshSpec& w = s.bodies[0].mesh.wall;
  CHECK(s.bodies[0].mesh.kind == MeshSpec::Kind::wall);
  CHECK(w.bond == WallMeshSpec::Bond::running);
  CHECK(w.units_per_course == 5);
  CHECK(w.courses == 3);
  CHECK(w.cells[0] == 4);
  CHECK(w.cells[2] == 2);
  CHECK(w.origin == Vec3(0, 1, 2));
  const ArchMeshSpec& a = s.bodies[1].mesh.arch;
  CHECK(a.kind == ArchMeshSpec::Kind::segmental);
  CHECK(a.half_angle == Approx(M_PI / 3));
  CHECK(a.abutments);
  CHECK(a.abutment_height == 0.5);
  CHECK(s.bodies[2].mesh.tower.blocks == 6);

  const std::string head = scene_head;
  CHECK_THAT(input_error(head + "    mesh: {wall: {unit: [0.2, 0.1, 0.05], courses: 3, length: "
                                "1.1}}\n"),
             Contains("scene.yaml:9:") && Contains("bodies[0].mesh.wall.length") &&
                 Contains("not a whole number of units") &&
                 Contains("6 units make 1.2 m, 5 make 1 m"));
  CHECK_THAT(
      input_error(head + "    mesh: {wall: {unit: [0.2, 0.1, 0.05], courses: 3, "
                         "units_per_course: 4, bond: running, cells_per_unit: [3, 1, 1]}}\n"),
      Contains("bodies[0].mesh.wall.cells_per_unit") && Contains("must be even"));
  CHECK_THAT(input_error(head + "    mesh: {wall: {unit: [0.2, 0.1, 0.05], course: 3}}\n"),
             Contains("bodies[0].mesh.wall.course") && Contains("Did you mean 'courses'?"));
  CHECK_THAT(input_error(head + "    mesh: {wall: {unit: [0.2, 0.1, 0.05], courses: 3, bond: "
                                "flemish, units_per_course: 2}}\n"),
             Contains("bodies[0].mesh.wall.bond") && Contains("Valid values: stack, running"));
  CHECK_THAT(input_error(head + "    mesh: {arch: {kind: segmental, radius: 2, thickness: 0.3, "
                                "depth: 0.5, voussoirs: 7}}\n"),
             Contains("bodies[0].mesh.arch.rise") && Contains("needs 'rise'"));
  CHECK_THAT(input_error(head + "    mesh: {arch: {kind: segmental, radius: 2, thickness: 0.3, "
                                "depth: 0.5, voussoirs: 7, rise: 2}}\n"),
             Contains("rise must be below the radius"));
  CHECK_THAT(input_error(head + "    mesh: {arch: {radius: 2, thickness: 0.3, depth: 0.5, "
                                "voussoirs: 7, rise: 1}}\n"),
             Contains("bodies[0].mesh.arch.rise") && Contains("segmental only"));
  CHECK_THAT(input_error(head + "    mesh: {tower: {block: [0.3, 0, 0.3], blocks: 6}}\n"),
             Contains("bodies[0].mesh.tower.block") && Contains("must be > 0"));
  CHECK_THAT(input_error(head + "    mesh: {tower: {block: [0.3, 0.3, 0.3], blocks: 6}, box: "
                                "{min: [0, 0, 0], max: [1, 1, 1]}}\n"),
             Contains("give one of box, file, wall, arch, tower"));
  CHECK_THAT(input_error(head + "    mesh: {tower: {block: [0.3, 0.3, 0.3], blocks: 6}}\n" +
                         "    joints: interfaces\n"),
             Contains("bodies[0].joints") && Contains("needs fracture properties"));
}

namespace {

// The whole body mesh put together from its chunks (nodes and tets by their whole-mesh number).
BodyMesh mesh_from_chunks(const BodyChunks& chunks, std::vector<std::int32_t>* tet_piece) {
  BodyMesh whole;
  whole.coords.assign(3 * static_cast<std::size_t>(chunks.n_nodes), std::nan(""));
  std::int64_t n_tets = 0;
  for (std::int64_t n : chunks.chunk_tets) n_tets += n;
  whole.tets.assign(4 * static_cast<std::size_t>(n_tets), -1);
  tet_piece->assign(static_cast<std::size_t>(n_tets), -1);
  REQUIRE(chunks.chunk_centre.size() == chunks.chunk_tets.size());
  for (std::size_t c = 0; c < chunks.chunk_tets.size(); ++c) {
    const MeshChunk chunk = chunks.generate(static_cast<std::int64_t>(c));
    REQUIRE(static_cast<std::int64_t>(chunk.mesh.tets.size() / 4) == chunks.chunk_tets[c]);
    REQUIRE(chunk.tet_id.size() == chunk.mesh.tets.size() / 4);
    for (std::size_t n = 0; n < chunk.node_id.size(); ++n)
      for (int k = 0; k < 3; ++k) {
        double& x = whole.coords[3 * static_cast<std::size_t>(chunk.node_id[n]) + k];
        // A node shared by two chunks has the same coordinates in both, bit for bit.
        if (!std::isnan(x)) REQUIRE(x == chunk.mesh.coords[3 * n + k]);
        x = chunk.mesh.coords[3 * n + k];
      }
    for (std::size_t t = 0; t < chunk.tet_id.size(); ++t) {
      const auto id = static_cast<std::size_t>(chunk.tet_id[t]);
      REQUIRE((*tet_piece)[id] == -1);  // every tet in exactly one chunk
      (*tet_piece)[id] = chunk.piece;
      for (int corner = 0; corner < 4; ++corner)
        whole.tets[4 * id + corner] = static_cast<LocalIndex>(
            chunk.node_id[static_cast<std::size_t>(chunk.mesh.tets[4 * t + corner])]);
    }
  }
  return whole;
}

void require_chunks_give(const MeshSpec& spec, const BodyMesh& expected, int ranks = 1) {
  const BodyChunks chunks = body_chunks(spec, ranks);
  std::vector<std::int32_t> tet_piece;
  const BodyMesh whole = mesh_from_chunks(chunks, &tet_piece);
  REQUIRE(whole.coords.size() == expected.coords.size());
  for (std::size_t i = 0; i < whole.coords.size(); ++i)
    REQUIRE(whole.coords[i] == expected.coords[i]);
  REQUIRE(whole.tets == expected.tets);
  std::int32_t n_pieces = 0;
  REQUIRE(tet_piece == connected_pieces(expected.tets,
                                        static_cast<LocalIndex>(expected.coords.size() / 3),
                                        &n_pieces));
  REQUIRE(n_pieces == chunks.n_pieces);
  REQUIRE(chunks.source == expected.source);  // messages name the mesh as the whole generator
}

}  // namespace

TEST_CASE("chunked generation gives the whole generator's mesh, node for node and tet for tet",
          "[drivers][generators]") {
  MeshSpec box;
  box.kind = MeshSpec::Kind::box;
  box.box.min = Vec3(-0.3, 0.1, -1.0 / 3.0);
  box.box.max = Vec3(0.7, 0.35, 0.2);
  box.box.cells[0] = 19;
  box.box.cells[1] = 30;
  box.box.cells[2] = 9;
  require_chunks_give(box, box_mesh(box.box));      // blocks of 4 cells, partial ones at the ends
  require_chunks_give(box, box_mesh(box.box), 64);  // blocks of 2 cells

  MeshSpec wall;
  wall.kind = MeshSpec::Kind::wall;
  wall.wall.bond = WallMeshSpec::Bond::running;
  wall.wall.unit = Vec3(0.3, 0.1, 0.07);
  wall.wall.courses = 3;
  wall.wall.units_per_course = 3;
  wall.wall.mortar_gap = 0.01;
  wall.wall.cells[0] = 4;
  require_chunks_give(wall, wall_mesh(wall.wall));

  MeshSpec tower;
  tower.kind = MeshSpec::Kind::tower;
  tower.tower.block = Vec3(0.2, 0.2, 0.15);
  tower.tower.blocks = 4;
  require_chunks_give(tower, tower_mesh(tower.tower));

  MeshSpec arch;
  arch.kind = MeshSpec::Kind::arch;
  arch.arch.radius = 1.0;
  arch.arch.thickness = 0.15;
  arch.arch.depth = 0.3;
  arch.arch.voussoirs = 7;
  arch.arch.abutments = true;
  arch.arch.abutment_width = 0.4;
  arch.arch.abutment_height = 0.5;
  require_chunks_give(arch, arch_mesh(arch.arch));

  MeshSpec file;
  file.kind = MeshSpec::Kind::file;
  file.file = "part.msh";
  REQUIRE_THROWS_AS(body_chunks(file), InputError);
}
