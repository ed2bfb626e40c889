// Pieces at their directory ranks (parallel/piece_directory) on 1–4 ranks: the motions of every
// rank's directory block equal one process's piece_motions bit for bit, with the nodes dealt to
// ranks by a hash of their gid (every piece split over the ranks) and in reversed order; rows
// appended with OrderedTextFile land in rank order, call after call.  (The start-up sums are
// compared with the serial builder in test_distributed_build.)
// Only CHECK here (no REQUIRE): a rank leaving a test case early would skip its collectives.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "core/dynamics.hpp"
#include "core/model_builder.hpp"
#include "drivers/mesh_generators.hpp"
#include "drivers/run_files.hpp"
#include "drivers/scene_builders.hpp"
#include "model_compare.hpp"
#include "parallel/communicator.hpp"
#include "parallel/ordered_text_file.hpp"
#include "parallel/piece_directory.hpp"

using namespace fdem;
using fdem::testing::same_bits;

namespace {

// A running-bond wall of 5 × 6 units beside a spinning box: 31 pieces.
Scene wall_scene() {
  Scene scene = builders::basic_scene(1.0);
  scene.materials.push_back(builders::elastic_material(2200, 1e9, 0.2));
  BodySpec box = builders::box_body("box", Vec3(-1, 0, 0), Vec3(-0.4, 0.3, 0.2), 5, 3, 2);
  box.velocity = Vec3(1, 0.5, 0);
  box.angular_velocity = Vec3(0, 0, 3);
  scene.bodies.push_back(box);
  BodySpec wall;
  wall.name = "wall";
  wall.material = 0;
  wall.mesh.kind = MeshSpec::Kind::wall;
  wall.mesh.wall.bond = WallMeshSpec::Bond::running;
  wall.mesh.wall.unit = Vec3(0.3, 0.15, 0.1);
  wall.mesh.wall.courses = 5;
  wall.mesh.wall.units_per_course = 6;
  wall.mesh.wall.mortar_gap = 0.002;
  wall.mesh.wall.cells[0] = 2;
  wall.angular_velocity = Vec3(0.5, 0, 0);
  scene.bodies.push_back(wall);
  return scene;
}

// The serial model moved and turned a little, node by node (a function of the gid), so that
// centroids, velocities and rotations are all non-trivial.
Model moved_model() {
  const Scene scene = wall_scene();
  Model model = build_model(scene, load_body_meshes(scene));
  NodeArrays& nodes = model.nodes;
  for (LocalIndex n = 0; n < nodes.size(); ++n) {
    const double g = static_cast<double>(nodes.gid[n]);
    const double turn = 0.01 * (model.nodes.piece[n] % 5);
    const Vec3 x0 = nodes.x0(n);
    vec3_at(nodes.x.data(), n) =
        x0 + Vec3(-turn * x0.y(), turn * x0.x(), 1e-4 * std::sin(g)) + Vec3(0.01, 0, 0.02);
    vec3_at(nodes.v.data(), n) += Vec3(1e-3 * std::cos(g), 0, 0);
  }
  return model;
}

// This rank's share of `whole`: the nodes whose gid hashes to it, owned, in reversed order.
Model dealt_model(const Model& whole, const Communicator& comm) {
  Model part;
  part.pieces = whole.pieces;
  keep_directory_block(part.pieces, comm);
  part.body_names = whole.body_names;
  std::vector<LocalIndex> mine;
  for (LocalIndex n = whole.nodes.size() - 1; n >= 0; --n)
    if ((whole.nodes.gid[n] * 2654435761u) % 97 % comm.size() == comm.rank()) mine.push_back(n);
  NodeArrays& nodes = part.nodes;
  nodes.resize(static_cast<LocalIndex>(mine.size()));
  nodes.n_owned = nodes.size();
  for (std::size_t i = 0; i < mine.size(); ++i) {
    const LocalIndex n = mine[i], j = static_cast<LocalIndex>(i);
    nodes.gid[j] = whole.nodes.gid[n];
    nodes.mass[j] = whole.nodes.mass[n];
    nodes.piece[j] = whole.nodes.piece[n];
    nodes.add_reference(j, whole.nodes.x0(n).data());
    for (int k = 0; k < 3; ++k) {
      nodes.x[3 * j + k] = whole.nodes.x[3 * n + k];
      nodes.v[3 * j + k] = whole.nodes.v[3 * n + k];
    }
  }
  return part;
}

}  // namespace

TEST_CASE("piece directory: each block's motions are one process's piece_motions, bit for bit",
          "[pieces]") {
  const Communicator comm;
  const Model whole = moved_model();
  const std::vector<PieceMotion> expected = piece_motions(whole);
  const Model part = dealt_model(whole, comm);
  const BlockMotions block = directory_piece_motions(part, comm);
  const PieceBlock ids = piece_directory_block(part.pieces, comm);
  CHECK(block.first == ids.begin);
  CHECK(block.motion.size() == static_cast<std::size_t>(ids.end - ids.begin));
  long mismatches = 0;
  double largest_turn = 0.0;
  for (std::size_t i = 0; i < block.motion.size(); ++i) {
    const PieceMotion& m = block.motion[i];
    const PieceMotion& e = expected[static_cast<std::size_t>(block.first) + i];
    for (int k = 0; k < 3; ++k)
      mismatches += !same_bits(m.centroid[k], e.centroid[k]) ||
                    !same_bits(m.velocity[k], e.velocity[k]) ||
                    !same_bits(m.rotation[k], e.rotation[k]);
    largest_turn = std::max(largest_turn, m.rotation.norm());
  }
  CHECK(mismatches == 0);
  CHECK(comm.max(largest_turn) > 0.03);  // the rotations are not all round-off
  CHECK(comm.sum(static_cast<std::int64_t>(block.motion.size())) ==
        static_cast<std::int64_t>(whole.pieces.size()));
}

TEST_CASE("piece directory: bodies.csv rows are the same text on any number of ranks", "[pieces]") {
  const Communicator comm;
  const Model whole = moved_model();
  const std::string expected = bodies_rows(0.5, whole, 0, piece_motions(whole));
  const Model part = dealt_model(whole, comm);
  const BlockMotions block = directory_piece_motions(part, comm);
  const std::string mine = bodies_rows(0.5, part, block.first, block.motion);
  std::vector<char> chars(mine.begin(), mine.end());
  const std::vector<char> all = comm.allgatherv(chars);
  CHECK(std::string(all.begin(), all.end()) == expected);
}

TEST_CASE("OrderedTextFile: every rank's text in rank order, appended call after call",
          "[pieces]") {
  const Communicator comm;
  const std::string dir =
      comm.broadcast((std::filesystem::temp_directory_path() / "fdem_ordered_text").string());
  const std::string path = dir + "/rows.csv";
  if (comm.rank() == 0) {
    std::filesystem::create_directories(dir);
    std::ofstream(path) << "header\n";
  }
  comm.barrier();
  OrderedTextFile file(path, 7, comm);
  std::ostringstream expected;
  expected << "header\n";
  for (int call = 0; call < 3; ++call) {
    for (int r = 0; r < comm.size(); ++r)  // rank 1 writes nothing in the second call
      if (!(call == 1 && r == 1)) expected << "call " << call << " rank " << r << '\n';
    std::ostringstream text;
    if (!(call == 1 && comm.rank() == 1))
      text << "call " << call << " rank " << comm.rank() << '\n';
    file.append(text.str());
  }
  comm.barrier();
  std::ifstream in(path);
  std::stringstream content;
  content << in.rdbuf();
  CHECK(content.str() == expected.str());
  comm.barrier();
  if (comm.rank() == 0) std::filesystem::remove_all(dir);
}
