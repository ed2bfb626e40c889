// Distributed start-up against the serial builder: on 1–4 ranks every rank's block of
// build_distributed_model holds exactly what build_model gives for those global ids (tets, nodes,
// masses, velocities, constraints, pieces; joints with their tets, nodes, areas and laws, contact
// groups, joint states, reach), bit for bit; the exact distributed median; a bad tet on one
// rank's chunk, a non-manifold face, touching pieces or an interface without a shared triangle
// stop every rank with the serial builder's message.
// Only CHECK here (no REQUIRE): a rank leaving a test case early would skip its collectives.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstring>
#include <numeric>
#include <random>
#include <vector>

#include "contact/contact_stage.hpp"
#include "core/error.hpp"
#include "core/model_builder.hpp"
#include "drivers/mesh_generators.hpp"
#include "drivers/scene_builders.hpp"
#include "model_compare.hpp"
#include "parallel/communicator.hpp"
#include "parallel/contact_faces_exchange.hpp"
#include "parallel/distributed_build.hpp"

using namespace fdem;
using fdem::testing::same_bits;

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

FractureSpec fracture(double strength) {
  FractureSpec f;
  f.tensile_strength = strength;
  f.cohesion = 2 * strength;
  f.friction_angle_deg = 30;
  f.energy_I = 1;
  f.energy_II = 5;
  return f;
}

// A `joints: all` bar with a cap bonded to its end face by an interface (split nodes on one
// side), a mortared running-bond wall (`joints: interfaces`, mortar gap 0) and two boxes of
// different cells along x sharing a face, bonded by an interface.
Scene jointed_scene() {
  Scene scene = builders::basic_scene(1.0);
  scene.source_path = "jointed.yaml";
  MaterialSpec rock = builders::elastic_material(2600, 2e9, 0.25);
  rock.name = "rock";
  rock.fracture = fracture(1e5);
  MaterialSpec brick = builders::elastic_material(1900, 5e9, 0.2);
  brick.name = "brick";
  brick.fracture = fracture(3e5);
  scene.materials = {rock, brick};
  BodySpec bar = builders::box_body("bar", Vec3(0, -0.05, -0.05), Vec3(0.6, 0.05, 0.05), 9, 3, 3);
  bar.joints = JointPlacement::all;
  bar.velocity = Vec3(2, 0, 0);
  scene.bodies.push_back(bar);
  scene.bodies.push_back(
      builders::box_body("cap", Vec3(0.6, -0.05, -0.05), Vec3(0.7, 0.05, 0.05), 1, 3, 3, 1));
  BodySpec wall;
  wall.name = "wall";
  wall.material = 1;
  wall.mesh.kind = MeshSpec::Kind::wall;
  wall.mesh.wall.bond = WallMeshSpec::Bond::running;
  wall.mesh.wall.unit = Vec3(0.24, 0.1, 0.07);
  wall.mesh.wall.courses = 4;
  wall.mesh.wall.units_per_course = 3;
  wall.mesh.wall.mortar_gap = 0.0;
  wall.mesh.wall.cells[0] = 4;
  wall.mesh.wall.origin = Vec3(0, 0.3, -0.1);
  wall.joints = JointPlacement::interfaces;
  scene.bodies.push_back(wall);
  scene.bodies.push_back(
      builders::box_body("left", Vec3(-0.5, -0.1, 0.3), Vec3(-0.2, 0.1, 0.5), 3, 4, 2));
  scene.bodies.push_back(
      builders::box_body("right", Vec3(-0.2, -0.1, 0.3), Vec3(0.1, 0.1, 0.5), 5, 4, 2, 1));
  InterfaceSpec end;
  end.body_a = 0;
  end.body_b = 1;
  end.fracture = fracture(5e4);
  InterfaceSpec boxes;
  boxes.body_a = 4;  // B before A in the scene: the match runs from A's faces
  boxes.body_b = 3;
  boxes.fracture = fracture(8e4);
  scene.interfaces = {end, boxes};
  return scene;
}

bool same_law(const JointLawSpec& a, const JointLawSpec& b) {
  const FractureSpec &f = a.fracture, &g = b.fracture;
  return a.origin == b.origin && same_bits(a.normal_penalty, b.normal_penalty) &&
         same_bits(a.tangential_penalty, b.tangential_penalty) &&
         same_bits(a.element_size, b.element_size) &&
         same_bits(f.tensile_strength, g.tensile_strength) && same_bits(f.cohesion, g.cohesion) &&
         same_bits(f.friction_angle_deg, g.friction_angle_deg) &&
         same_bits(f.energy_I, g.energy_I) && same_bits(f.energy_II, g.energy_II) &&
         same_bits(f.softening_a, g.softening_a) && same_bits(f.softening_b, g.softening_b) &&
         same_bits(f.softening_c, g.softening_c);
}

// The message every rank gets from build_distributed_model, without the "rank R: " prefix (empty
// when it did not throw).
std::string distributed_message(const Scene& scene, const std::vector<BodyChunks>& chunks,
                                const Communicator& comm) {
  try {
    build_distributed_model(scene, chunks, comm);
  } catch (const InputError& e) {
    const std::string what = e.what();
    const std::size_t colon = what.find(": ");
    return what.rfind("rank ", 0) == 0 && colon != std::string::npos ? what.substr(colon + 2)
                                                                     : what;
  }
  return "";
}

std::string serial_message(const Scene& scene, const std::vector<BodyMesh>& meshes) {
  try {
    build_model(scene, meshes);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
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
  Scene scene = mixed_scene();
  // Gids from 0, and from above 2^32 (parallel.gid_offset) in both builders.
  scene.parallel.gid_offset = GENERATE(GlobalId{0}, (GlobalId{1} << 32) + 12345);
  INFO("gid offset " << scene.parallel.gid_offset);
  const Model serial = build_model(scene, load_body_meshes(scene));  // gid = offset + index
  const DistributedModel block =
      build_distributed_model(scene, chunks_of(scene, comm.size()), comm);
  testing::check_block_is_serial_model(block, serial, comm);
}

TEST_CASE(
    "distributed start-up: corner contact's surface, fold and fold-vertex bits are the "
    "serial builder's, tet by tet",
    "[mpi][distributed_build][corner_contact]") {
  const Communicator comm = Communicator::world();
  Scene scene = mixed_scene();
  scene.contact_formulation = ContactFormulation::corners;
  const Model serial = build_model(scene, load_body_meshes(scene));
  REQUIRE(serial.tets.contact_faces.size() == 2 * static_cast<std::size_t>(serial.tets.size()));
  DistributedModel block = build_distributed_model(scene, chunks_of(scene, comm.size()), comm);
  compute_contact_faces(block.model, comm);
  const Model& local = block.model;
  REQUIRE(local.tets.contact_faces.size() == 2 * static_cast<std::size_t>(local.tets.size()));
  long mismatches = 0, surface = 0;
  for (LocalIndex t = 0; t < local.tets.size(); ++t) {
    const auto g = static_cast<std::size_t>(local.tets.gid[t] - serial.gid_offset);
    for (int k = 0; k < 2; ++k)
      mismatches += local.tets.contact_faces[2 * t + k] != serial.tets.contact_faces[2 * g + k];
    surface += (local.tets.contact_faces[2 * t] & 0xF) != 0;
  }
  CHECK(comm.sum(mismatches) == 0);
  CHECK(comm.sum(surface) > 0);
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

TEST_CASE("distributed start-up: joints, contact groups and joint states are the serial builder's",
          "[mpi][distributed_build]") {
  const Communicator comm = Communicator::world();
  Scene scene = jointed_scene();
  scene.parallel.gid_offset = GENERATE(GlobalId{0}, (GlobalId{1} << 40) - 7);
  INFO("gid offset " << scene.parallel.gid_offset);
  const GlobalId offset = scene.parallel.gid_offset;
  const Model serial = build_model(scene, load_body_meshes(scene));  // gid = offset + index
  const DistributedModel block =
      build_distributed_model(scene, chunks_of(scene, comm.size()), comm);
  const Model& local = block.model;
  testing::check_block_is_serial_model(block, serial, comm);
  const LocalIndex n_serial = serial.joints.size();
  CHECK(n_serial > 500);
  CHECK(block.n_joints == n_serial);
  CHECK(comm.sum(static_cast<std::int64_t>(block.joints.size())) == n_serial);
  CHECK(block.n_nodes == serial.nodes.size());
  // Laws: the same list (numbered by (group, bin)), several groups and sizes.
  CHECK(serial.joint_laws.size() > 4);
  CHECK(local.joint_laws.size() == serial.joint_laws.size());
  long law_mismatches = 0;
  for (std::size_t l = 0; l < std::min(local.joint_laws.size(), serial.joint_laws.size()); ++l)
    law_mismatches += !same_law(local.joint_laws[l], serial.joint_laws[l]);
  CHECK(law_mismatches == 0);
  // Every joint: gid, tets, nodes, area, law; tet A in this block; ascending gid.
  long joint_mismatches = 0;
  GlobalId previous = -1;
  for (const StartJoint& j : block.joints) {
    const auto g = static_cast<std::size_t>(j.gid - offset);
    bool same = j.gid > previous && j.gid >= offset && j.gid < offset + n_serial &&
                j.tets[0] >= block.tet_block[comm.rank()] &&
                j.tets[0] < block.tet_block[comm.rank() + 1];
    previous = j.gid;
    if (same) {
      same = serial.joints.gid[g] == j.gid && same_bits(serial.joints.area0[g], j.area0) &&
             serial.joints.law[g] == j.law;
      for (int i = 0; i < 2; ++i)
        same = same && serial.tets.gid[serial.joints.tets[2 * g + i]] == j.tets[i];
      for (int i = 0; i < 6; ++i)
        same = same && serial.nodes.gid[serial.joints.nodes[6 * g + i]] == j.nodes[i];
    }
    joint_mismatches += !same;
  }
  CHECK(joint_mismatches == 0);
  // Serial joint states (bonded tets) and reach (largest extent over the tets sharing a node or a
  // joint) against each local tet; contact groups (each bar tet its own).
  std::vector<char> bonded(static_cast<std::size_t>(serial.tets.size()), 0);
  std::vector<double> extent(static_cast<std::size_t>(serial.tets.size()));
  std::vector<double> node_extent(static_cast<std::size_t>(serial.nodes.size()), 0.0);
  for (LocalIndex t = 0; t < serial.tets.size(); ++t) {
    Vec3 lo = serial.nodes.x0(serial.tets.nodes[4 * t]), hi = lo;
    for (int c = 1; c < 4; ++c) {
      lo = lo.cwiseMin(serial.nodes.x0(serial.tets.nodes[4 * t + c]));
      hi = hi.cwiseMax(serial.nodes.x0(serial.tets.nodes[4 * t + c]));
    }
    extent[t] = (hi - lo).maxCoeff();
    for (int c = 0; c < 4; ++c)
      node_extent[serial.tets.nodes[4 * t + c]] =
          std::max(node_extent[serial.tets.nodes[4 * t + c]], extent[t]);
  }
  std::vector<double> reach(extent);
  for (LocalIndex t = 0; t < serial.tets.size(); ++t)
    for (int c = 0; c < 4; ++c)
      reach[t] = std::max(reach[t], node_extent[serial.tets.nodes[4 * t + c]]);
  for (LocalIndex j = 0; j < n_serial; ++j) {
    const LocalIndex a = serial.joints.tets[2 * j], b = serial.joints.tets[2 * j + 1];
    bonded[a] = bonded[b] = 1;
    reach[a] = std::max(reach[a], extent[b]);
    reach[b] = std::max(reach[b], extent[a]);
  }
  // Enclosed bar tets (no corner on the bar's surface): the distributed start finds the same.
  REQUIRE(serial.tets.enclosed.size() == static_cast<std::size_t>(serial.tets.size()));
  long enclosed = 0;
  for (LocalIndex t = 0; t < serial.tets.size(); ++t)
    if (serial.tets.enclosed[t]) {
      CHECK(bonded[t] == 1);
      bonded[t] = static_cast<char>(fdem::TetJointState::enclosed);
      ++enclosed;
    }
  CHECK(enclosed > 0);
  CHECK(block.tet_joint_state.size() == static_cast<std::size_t>(local.tets.size()));
  CHECK(block.tet_reach.size() == static_cast<std::size_t>(local.tets.size()));
  long tet_mismatches = 0;
  for (LocalIndex t = 0; t < local.tets.size() && block.tet_joint_state.size() ==
                                                      static_cast<std::size_t>(local.tets.size());
       ++t) {
    const auto g = static_cast<std::size_t>(local.tets.gid[t] - offset);
    bool same = local.tets.group_of(t) == serial.tets.group_of(static_cast<LocalIndex>(g)) &&
                block.tet_joint_state[t] == bonded[g] && same_bits(block.tet_reach[t], reach[g]);
    for (int c = 0; c < 4; ++c)
      same = same &&
             local.nodes.gid[local.tets.nodes[4 * t + c]] ==
                 serial.nodes.gid[serial.tets.nodes[4 * g + c]] &&
             same_bits(local.nodes.mass[local.tets.nodes[4 * t + c]],
                       serial.nodes.mass[serial.tets.nodes[4 * g + c]]);
    tet_mismatches += !same;
  }
  CHECK(tet_mismatches == 0);
}

TEST_CASE(
    "distributed start-up: joints that cannot be placed stop every rank as the serial builder",
    "[mpi][distributed_build]") {
  const Communicator comm = Communicator::world();
  SECTION("a triangle of three tetrahedra") {
    // The right box's first chunk gets a copy of its first tet: its inner faces have three tets.
    const Scene scene = jointed_scene();
    std::vector<BodyChunks> chunks = chunks_of(scene, comm.size());
    BodyChunks& right = chunks[4];
    right.chunk_tets[0] += 1;
    const auto make = right.generate;
    right.generate = [make](std::int64_t c) {
      MeshChunk chunk = make(c);
      if (c == 0) {
        chunk.mesh.tets.insert(chunk.mesh.tets.end(), chunk.mesh.tets.begin(),
                               chunk.mesh.tets.begin() + 4);
        chunk.tet_id.push_back(1000000);
      }
      return chunk;
    };
    std::vector<BodyMesh> meshes = load_body_meshes(scene);
    meshes[4].tets.insert(meshes[4].tets.end(), meshes[4].tets.begin(), meshes[4].tets.begin() + 4);
    const std::string expected = serial_message(scene, meshes);
    CHECK(expected.find("a triangle is shared by more than two tetrahedra") != std::string::npos);
    CHECK(distributed_message(scene, chunks, comm) == expected);
  }
  SECTION("touching pieces without a shared triangle") {
    Scene scene = jointed_scene();
    scene.bodies[2].mesh.wall.mortar_gap = 0.005;
    const std::string expected = serial_message(scene, load_body_meshes(scene));
    CHECK(expected.find("no two of its pieces share a triangle") != std::string::npos);
    CHECK(distributed_message(scene, chunks_of(scene, comm.size()), comm) == expected);
  }
  SECTION("an interface without a shared triangle") {
    Scene scene = jointed_scene();
    scene.bodies[4].mesh.box.min.x() += 0.01;
    const std::string expected = serial_message(scene, load_body_meshes(scene));
    CHECK(expected.find("interfaces[1] between 'right' and 'left': no boundary triangle") !=
          std::string::npos);
    CHECK(distributed_message(scene, chunks_of(scene, comm.size()), comm) == expected);
  }
}
