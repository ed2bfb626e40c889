// Gmsh meshes on N ranks (parallel/file_mesh_chunks, distributed_pieces): the distributed start-up
// from a model file equals the serial builder's model from the .msh bit for bit (two pieces
// interleaved in the file, physical selections, ASCII and binary, a Gmsh-made disc); the
// distributed union-find numbers pieces as connected_pieces does; a damaged block found by one
// rank stops every rank with that rank's message.  Runs on 1–4 ranks (tests/CMakeLists.txt).
// Only CHECK here (no REQUIRE): a rank leaving a test case early would skip its collectives.
#include <hdf5.h>

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "core/error.hpp"
#include "core/model_builder.hpp"
#include "drivers/mesh_generators.hpp"
#include "drivers/scene_builders.hpp"
#include "model_compare.hpp"
#include "parallel/communicator.hpp"
#include "parallel/distributed_build.hpp"
#include "parallel/distributed_pieces.hpp"
#include "parallel/file_mesh_chunks.hpp"
#include "parallel/model_file.hpp"

using namespace fdem;

namespace {

namespace fs = std::filesystem;

std::string data_file(const std::string& name) {
  return std::string(FDEM_TEST_DATA) + "/gmsh/" + name;
}

// A directory of this run's own (2-, 3- and 4-rank runs may run at the same time).
std::string scratch(const Communicator& comm, const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("fdem_test_file_mesh_" + std::to_string(comm.size()));
  if (comm.is_root()) fs::create_directories(dir);
  comm.barrier();
  return (dir / name).string();
}

// Rank 0 prepares `msh` into `h5` (small blocks and window: many of each); every rank waits.
void prepare(const Communicator& comm, const std::string& msh, const std::string& h5) {
  comm.run_collectively([&] {
    if (comm.is_root()) prepare_model_file(msh, h5, {5, 64});
  });
}

// The Gmsh body (body 0) of `msh`, spinning and flying, a generated box beside it, a clamp.
Scene gmsh_scene(const std::string& msh, const std::string& physical) {
  Scene scene = builders::basic_scene(1.0);
  scene.materials.push_back(builders::elastic_material(2400, 1e9, 0.2));
  MaterialSpec damped = builders::elastic_material(1100, 5e6, 0.3);
  damped.name = "damped";
  damped.damping = 0.02;
  scene.materials.push_back(damped);
  BodySpec body;
  body.name = "gmsh";
  body.material = 1;
  body.mesh.kind = MeshSpec::Kind::file;
  body.mesh.file = msh;
  body.mesh.physical = physical;
  body.velocity = Vec3(0.3, -1, 0);
  body.angular_velocity = Vec3(1, 0, 7);
  scene.bodies.push_back(body);
  scene.bodies.push_back(
      builders::box_body("box", Vec3(-0.5, -0.5, -0.3), Vec3(0.7, 0.5, -0.05), 7, 5, 2));
  scene.loads.push_back(builders::load_on_region(Vec3(-1, -1, -1), Vec3(0.05, 1, 1), Vec3::Zero()));
  return scene;
}

// The distributed start-up with body 0 read from the model file `h5`.
DistributedModel distributed_start(const Scene& scene, const std::string& h5,
                                   const Communicator& comm) {
  std::vector<BodyChunks> chunks(scene.bodies.size());
  for (std::size_t b = 1; b < scene.bodies.size(); ++b)
    chunks[b] = body_chunks(scene.bodies[b].mesh, comm.size());
  chunks[0] =
      file_mesh_chunks(h5, scene.bodies[0].mesh.physical, mesh_source(scene.bodies[0].mesh), comm);
  return build_distributed_model(scene, chunks, comm);
}

// The message of the InputError every rank must throw, checked to be collective and the same.
std::string collective_error(const Communicator& comm, const std::function<void()>& f,
                             int* first_rank) {
  std::string message;
  bool collective = false;
  try {
    f();
  } catch (const InputError& e) {
    message = e.what();
    const auto* c = dynamic_cast<const CollectiveFailure*>(&e);
    collective = c != nullptr;
    if (c) *first_rank = c->first_rank();
  }
  CHECK(collective);
  CHECK(comm.broadcast(message, 0) == message);
  return message;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("distributed start-up from a Gmsh model file is the serial builder's model",
          "[mpi][file_mesh]") {
  const Communicator comm = Communicator::world();
  struct Case {
    const char* mesh;
    const char* physical;
  };
  for (const Case& c :
       {Case{"two_blocks.msh", "all"}, Case{"two_blocks_binary.msh", ""},
        Case{"two_blocks.msh", "box2"}, Case{"two_blocks.msh", "1"},
        Case{"brazilian_disc_coarse.msh", "disc"},
        // Gmsh writes each volume's tets together: on 3-4 ranks the last slices
        // hold no "left" tet, the first none of "right".
        Case{"cube_two_volumes_ascii.msh", "left"}, Case{"cube_two_volumes_binary.msh", "right"},
        Case{"cube_two_volumes_ascii.msh", ""}}) {
    INFO(c.mesh << " [" << c.physical << "] on " << comm.size() << " ranks");
    const std::string msh = data_file(c.mesh), h5 = scratch(comm, "model.h5");
    prepare(comm, msh, h5);
    const Scene scene = gmsh_scene(msh, c.physical);
    const Model serial = build_model(scene, load_body_meshes(scene));  // from the .msh
    const DistributedModel block = distributed_start(scene, h5, comm);
    testing::check_block_is_serial_model(block, serial, comm);
    if (std::string(c.physical) == "all") CHECK(serial.pieces.size() == 3);  // 2 + the box
    // One rank from the model file: the same model as from the .msh.
    Scene from_h5 = scene;
    from_h5.bodies[0].mesh.file = h5;
    const Model serial_h5 = build_model(from_h5, load_body_meshes(from_h5));
    CHECK(serial_h5.tets.size() == serial.tets.size());
    long differences = 0;
    for (LocalIndex n = 0; n < serial.nodes.size() && n < serial_h5.nodes.size(); ++n)
      for (int k = 0; k < 3; ++k)
        differences += !testing::same_bits(serial.nodes.x0(n)[k], serial_h5.nodes.x0(n)[k]);
    for (std::size_t i = 0; i < serial.tets.nodes.size() && i < serial_h5.tets.nodes.size(); ++i)
      differences += serial.tets.nodes[i] != serial_h5.tets.nodes[i];
    CHECK(differences == 0);
  }
}

TEST_CASE("distributed union-find numbers pieces as connected_pieces does", "[mpi][file_mesh]") {
  const Communicator comm = Communicator::world();
  // The same mesh on every rank: chains of tets (each tet shares three nodes with the next), node
  // ids scattered, tets shuffled, so that every piece is cut into many fragments across ranks.
  std::mt19937_64 random(2024);
  std::vector<std::array<std::int64_t, 4>> all;
  std::int64_t n_nodes = 0;
  for (int piece = 0; piece < 40; ++piece) {
    const int length = piece % 7 == 0 ? 1 : 3 + static_cast<int>(random() % 60);
    for (int t = 0; t < length; ++t)
      all.push_back({n_nodes + t, n_nodes + t + 1, n_nodes + t + 2, n_nodes + t + 3});
    n_nodes += length + 3;
  }
  std::vector<std::int64_t> permutation(static_cast<std::size_t>(n_nodes + 17));
  std::iota(permutation.begin(), permutation.end(), 0);
  std::shuffle(permutation.begin(), permutation.end(), random);
  std::shuffle(all.begin(), all.end(), random);
  std::vector<LocalIndex> whole;
  for (auto& tet : all)
    for (std::int64_t& node : tet) {
      node = permutation[static_cast<std::size_t>(node)];
      whole.push_back(static_cast<LocalIndex>(node));
    }
  std::int32_t serial_count = 0;
  const std::vector<std::int32_t> serial =
      connected_pieces(whole, static_cast<LocalIndex>(permutation.size()), &serial_count);
  const auto m = static_cast<std::int64_t>(all.size());
  const std::int64_t first = mul_div(m, comm.rank(), comm.size()),
                     last = mul_div(m, comm.rank() + 1, comm.size());
  std::vector<std::int64_t> local;
  for (std::int64_t t = first; t < last; ++t)
    local.insert(local.end(), all[std::size_t(t)].begin(), all[std::size_t(t)].end());
  std::int32_t count = 0;
  const std::vector<std::int32_t> pieces =
      distributed_pieces(local, static_cast<std::int64_t>(permutation.size()), first, comm, &count);
  CHECK(count == serial_count);
  long mismatches = 0;
  for (std::int64_t t = first; t < last; ++t)
    mismatches += pieces[std::size_t(t - first)] != serial[std::size_t(t)];
  CHECK(mismatches == 0);
}

TEST_CASE("a damaged block of a model file stops every rank with the finder's message",
          "[mpi][file_mesh]") {
  const Communicator comm = Communicator::world();
  const int last_rank = comm.size() - 1;
  const std::string msh = data_file("two_blocks.msh"), good = scratch(comm, "good.h5"),
                    bad = scratch(comm, "bad.h5");
  prepare(comm, msh, good);
  const Scene scene = gmsh_scene(msh, "all");
  // Rank 0 writes `bad` from the good file's content changed by `damage`.
  const auto damaged = [&](const std::function<void(ModelFileContent&)>& damage) {
    comm.run_collectively([&] {
      if (!comm.is_root()) return;
      ModelFileContent content = read_model_file_content(good);
      damage(content);
      write_model_file(content, bad);
    });
  };
  const std::int64_t m = read_model_file_header(good).n_tets;
  const std::int64_t n = read_model_file_header(good).n_nodes;
  const std::string expected_rank =
      comm.size() > 1 ? "rank " + std::to_string(last_rank) + ": " : "";
  int first_rank = -1;

  SECTION("a tet referencing a node beyond the table, in the last rank's slice") {
    damaged([&](ModelFileContent& c) { c.tet_nodes[std::size_t(4 * (m - 2) + 1)] = n + 7; });
    const std::string message = collective_error(
        comm, [&] { distributed_start(scene, bad, comm); }, &first_rank);
    CHECK(first_rank == last_rank);
    CHECK(contains(message, expected_rank + "model file '" + bad + "'"));
    CHECK(contains(message, "references node row " + std::to_string(n + 7) +
                                ", but the node table has " + std::to_string(n) + " rows"));
  }
  SECTION("a NaN coordinate of a node only the last tet uses") {
    std::int64_t tag = 0;
    damaged([&](ModelFileContent& c) {
      // A node of the last tet that no other tet uses, if there is one; else its first node.
      std::int64_t row = c.tet_nodes[std::size_t(4 * (m - 1))];
      for (int k = 0; k < 4; ++k) {
        const std::int64_t r = c.tet_nodes[std::size_t(4 * (m - 1) + k)];
        if (std::count(c.tet_nodes.begin(), c.tet_nodes.end(), r) == 1) row = r;
      }
      c.node_x[std::size_t(3 * row + 2)] = std::numeric_limits<double>::quiet_NaN();
      tag = c.node_tag[std::size_t(row)];
    });
    tag = comm.max(tag);
    const std::string message = collective_error(
        comm, [&] { distributed_start(scene, bad, comm); }, &first_rank);
    CHECK(contains(message, "model file '" + bad + "'"));
    CHECK(contains(message, "node " + std::to_string(tag) + " has a coordinate that is NaN"));
  }
  SECTION("an inverted tet") {
    std::int64_t tag = 0;
    damaged([&](ModelFileContent& c) {
      std::swap(c.tet_nodes[std::size_t(4 * (m - 1) + 2)],
                c.tet_nodes[std::size_t(4 * (m - 1) + 3)]);
      tag = c.tet_tag[std::size_t(m - 1)];
    });
    tag = comm.max(tag);
    const std::string message = collective_error(
        comm, [&] { distributed_start(scene, bad, comm); }, &first_rank);
    CHECK(first_rank == last_rank);
    CHECK(contains(message, expected_rank + "body 'gmsh' (" + msh + " [all]): tetrahedron " +
                                std::to_string(tag) + " is inverted"));
  }
  SECTION("a value changed after writing: the dataset's checksum") {
    comm.run_collectively([&] {
      if (!comm.is_root()) return;
      fs::copy_file(good, bad, fs::copy_options::overwrite_existing);
      const hid_t file = H5Fopen(bad.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
      const hid_t dataset = H5Dopen2(file, "/nodes/x", H5P_DEFAULT);
      const hid_t space = H5Dget_space(dataset);
      const std::array<hsize_t, 2> start{3, 1}, count{1, 1};
      H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
      const hsize_t one = 1;
      const hid_t memory = H5Screate_simple(1, &one, nullptr);
      const double moved = 0.123456;
      H5Dwrite(dataset, H5T_NATIVE_DOUBLE, memory, space, H5P_DEFAULT, &moved);
      H5Sclose(memory);
      H5Sclose(space);
      H5Dclose(dataset);
      H5Fclose(file);
    });
    const std::string message = collective_error(
        comm, [&] { distributed_start(scene, bad, comm); }, &first_rank);
    CHECK(contains(message,
                   "model file '" + bad + "': dataset /nodes/x does not match its checksum"));
  }
}
