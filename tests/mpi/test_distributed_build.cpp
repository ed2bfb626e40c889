// Distributed start-up against the serial builder: on 1–4 ranks every rank's block of
// build_distributed_model holds exactly what build_model gives for those global ids (tets, nodes,
// masses, velocities, constraints, pieces), bit for bit; the exact distributed median; a bad tet on
// one rank's chunk stops every rank with the serial builder's message.
// Only CHECK here (no REQUIRE): a rank leaving a test case early would skip its collectives.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstring>
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

using namespace fdem;

namespace {

// A spinning box, a running-bond wall of 3 × 3 units on it, a 7-voussoir arch and a fixed base;
// a clamped region and a damped material, so that every field the builder sets is exercised.
Scene mixed_scene() {
  Scene scene = builders::basic_scene(1.0);
  scene.materials.push_back(builders::elastic_material(2400, 1e9, 0.2));
  MaterialSpec damped =
      builders::elastic_material(1100, 5e6, 0.3, ElasticModel::st_venant_kirchhoff);
  damped.name = "damped";
  damped.damping = 0.02;
  scene.materials.push_back(damped);
  BodySpec base = builders::box_body("base", Vec3(-1, -0.5, -0.3), Vec3(2, 0.5, 0), 13, 5, 3);
  base.fixed = true;
  scene.bodies.push_back(base);
  BodySpec spin =
      builders::box_body("spin", Vec3(-0.9, -0.3, 1.2), Vec3(-0.2, 0.31, 1.5), 9, 7, 4, 1);
  spin.velocity = Vec3(1, 0, -0.5);
  spin.angular_velocity = Vec3(0.3, 0, 20);
  scene.bodies.push_back(spin);
  BodySpec wall;
  wall.name = "wall";
  wall.material = 0;
  wall.mesh.kind = MeshSpec::Kind::wall;
  wall.mesh.wall.bond = WallMeshSpec::Bond::running;
  wall.mesh.wall.unit = Vec3(0.3, 0.1, 0.07);
  wall.mesh.wall.courses = 3;
  wall.mesh.wall.units_per_course = 3;
  wall.mesh.wall.mortar_gap = 0.002;
  wall.mesh.wall.cells[0] = 4;
  wall.mesh.wall.origin = Vec3(0, -0.05, 0);
  wall.velocity = Vec3(0, 0.1, 0);
  scene.bodies.push_back(wall);
  BodySpec arch;
  arch.name = "arch";
  arch.material = 1;
  arch.mesh.kind = MeshSpec::Kind::arch;
  arch.mesh.arch.radius = 0.5;
  arch.mesh.arch.thickness = 0.08;
  arch.mesh.arch.depth = 0.2;
  arch.mesh.arch.voussoirs = 7;
  arch.mesh.arch.origin = Vec3(1.2, -0.1, 0.3);
  arch.angular_velocity = Vec3(0, 2, 0);
  scene.bodies.push_back(arch);
  LoadSpec clamp;
  clamp.region = RegionSpec{Vec3(-1, -1, -1), Vec3(-0.5, 1, 1.6)};
  clamp.velocity = Vec3(0, 0, 0);
  scene.loads.push_back(clamp);
  return scene;
}

std::vector<BodyChunks> chunks_of(const Scene& scene, int ranks) {
  std::vector<BodyChunks> chunks;
  for (const BodySpec& body : scene.bodies) chunks.push_back(body_chunks(body.mesh, ranks));
  return chunks;
}

}  // namespace

TEST_CASE("distributed start-up: each rank's block is the serial builder's model, bit for bit",
          "[mpi][distributed_build]") {
  const Communicator comm = Communicator::world();
  const Scene scene = mixed_scene();
  const Model serial = build_model(scene, load_body_meshes(scene));  // gid = index
  const DistributedModel block =
      build_distributed_model(scene, chunks_of(scene, comm.size()), comm);
  testing::check_block_is_serial_model(block, serial, comm);
}

TEST_CASE("distributed start-up: an inverted tet on one rank's chunk stops every rank",
          "[mpi][distributed_build]") {
  const Communicator comm = Communicator::world();
  Scene scene = mixed_scene();
  std::vector<BodyChunks> chunks = chunks_of(scene, comm.size());
  // The wall's last unit comes out mirrored (inverted tets); whichever rank generates it fails.
  const auto make = chunks[2].generate;
  const std::int64_t last = static_cast<std::int64_t>(chunks[2].chunk_tets.size()) - 1;
  chunks[2].generate = [make, last](std::int64_t unit) {
    MeshChunk chunk = make(unit);
    if (unit == last)
      for (std::size_t t = 0; t < chunk.mesh.tets.size() / 4; ++t)
        std::swap(chunk.mesh.tets[4 * t + 2], chunk.mesh.tets[4 * t + 3]);
    return chunk;
  };
  std::string message;
  try {
    build_distributed_model(scene, chunks, comm);
  } catch (const InputError& e) {
    message = e.what();
  }
  CHECK(message.find("body 'wall'") != std::string::npos);
  CHECK(message.find("is inverted") != std::string::npos);
}

TEST_CASE("distributed_nth_value is the exact k-th smallest over all ranks",
          "[mpi][distributed_build]") {
  const Communicator comm = Communicator::world();
  std::mt19937_64 random(7);  // the same sequence on every rank: each takes its share
  std::uniform_real_distribution<double> uniform(0.0, 3.0);
  std::vector<double> all(1001);
  for (double& v : all) v = uniform(random);
  all[17] = 0.0;
  all[500] = all[501];  // ties
  std::vector<double> mine;
  for (std::size_t i = static_cast<std::size_t>(comm.rank()); i < all.size();
       i += static_cast<std::size_t>(comm.size()))
    mine.push_back(all[i]);
  std::vector<double> sorted = all;
  std::sort(sorted.begin(), sorted.end());
  for (std::int64_t k : {std::int64_t{0}, std::int64_t{1}, std::int64_t{500}, std::int64_t{1000}})
    CHECK(testing::same_bits(distributed_nth_value(mine, k, comm),
                             sorted[static_cast<std::size_t>(k)]));
}
