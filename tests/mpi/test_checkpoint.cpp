// Checkpoint files on 1–4 ranks: collective write of owned rows into one HDF5 file, read back
// everywhere bit-exactly, any writer count, temp file + rename (errors:
// test_checkpoint_errors.cpp). Only CHECK here (no REQUIRE): a rank leaving a test case early would
// skip its collectives.
#include <catch2/catch.hpp>

#include "checkpoint_test_rows.hpp"

using namespace fdem;
using namespace fdem::checkpoint_test;

TEST_CASE("checkpoint: interleaved rows of every rank round-trip bit-exactly",
          "[mpi][checkpoint]") {
  const Communicator comm = Communicator::world();
  INFO("rank " << comm.rank() << " of " << comm.size());
  const SharedTempDir dir(comm, "checkpoint");
  const FileScene scene;
  const std::string path = dir.file("state.h5");
  const CheckpointHeader header = make_header(scene);
  const CheckpointRows owned = interleaved(scene, comm.rank(), comm.size());

  CHECK(caught([&] { write_checkpoint(path, comm, header, owned); }) == "none");
  std::pair<CheckpointHeader, CheckpointRows> back;
  CHECK(caught([&] { back = read_checkpoint(path, comm); }) == "none");
  check_header_equal(back.first, header, comm.size());
  check_rows_equal(back.second, expected_rows(scene, comm.size()));
  CHECK(back.second.nodes.gid.size() == 1000);
  CHECK(back.second.joints.gid.size() == 300);
  CHECK(back.second.pair_a.size() == static_cast<std::size_t>(3 * comm.size()));
  // The datasets are the field tables' (core/fields.hpp).
  CHECK(back.second.field_list() ==
        "nodes/x:float64[3] nodes/v:float64[3] nodes/prescribed_velocity:float64[3] "
        "nodes/x_at_detection:float64[3] joints/broken:uint8[1] joints/mode:uint8[1] "
        "joints/history:uint8[12] "
        "friction/spring:float64[3] friction/stiffness:float64[1] friction/anchor_a:float64[4] "
        "friction/anchor_b:float64[4]");
}

TEST_CASE("checkpoint: a rank without rows takes part, empty joint and friction tables",
          "[mpi][checkpoint]") {
  const Communicator comm = Communicator::world();
  INFO("rank " << comm.rank() << " of " << comm.size());
  const SharedTempDir dir(comm, "checkpoint");
  const int last = comm.size() - 1;

  SECTION("the last rank owns nothing (on one rank: it owns everything)") {
    FileScene scene;
    scene.friction_per_writer = 0;
    const int holders = std::max(1, comm.size() - 1);
    CheckpointRows owned = make_owned(
        scene, comm.rank(), [&](GlobalId g) { return static_cast<int>(g % holders); },
        [&](GlobalId j) { return static_cast<int>((j * 5) % holders); });
    // The ranks that hold rows also hold the friction pairs, except the idle last rank.
    if (comm.size() == 1 || comm.rank() != last) {
      FileScene with_friction = scene;
      with_friction.friction_per_writer = 2;
      add_friction(owned, with_friction, comm.rank());
    }
    if (comm.size() > 1 && comm.rank() == last) {
      CHECK(owned.nodes.gid.empty());
      CHECK(owned.joints.gid.empty());
      CHECK(owned.pair_a.empty());
    }
    const std::string path = dir.file("idle.h5");
    CHECK(caught([&] { write_checkpoint(path, comm, make_header(scene), owned); }) == "none");
    std::pair<CheckpointHeader, CheckpointRows> back;
    CHECK(caught([&] { back = read_checkpoint(path, comm); }) == "none");
    FileScene expected_scene = scene;
    expected_scene.friction_per_writer = 2;
    check_rows_equal(back.second, expected_rows(expected_scene, holders));
  }

  SECTION("a scene without joints or friction: zero-size datasets") {
    FileScene scene;
    scene.n_joints = 0;
    scene.history_bytes = 0;
    scene.friction_per_writer = 0;
    const CheckpointRows owned = interleaved(scene, comm.rank(), comm.size());
    CheckpointHeader header = make_header(scene);
    header.doubles.clear();
    header.integers.clear();
    const std::string path = dir.file("no_joints.h5");
    CHECK(caught([&] { write_checkpoint(path, comm, header, owned); }) == "none");
    std::pair<CheckpointHeader, CheckpointRows> back;
    CHECK(caught([&] { back = read_checkpoint(path, comm); }) == "none");
    check_header_equal(back.first, header, comm.size());
    check_rows_equal(back.second, expected_rows(scene, comm.size()));
    CHECK(back.second.joints.gid.empty());
    CHECK(back.second.joints.column("history").size() == 0);
    CHECK(back.second.pair_a.empty());
    CHECK(back.second.nodes.gid.size() == 1000);
  }

  SECTION("no nodes at all") {
    FileScene scene;
    scene.n_nodes = 0;
    scene.n_joints = 0;
    scene.history_bytes = 3;
    scene.friction_per_writer = 0;
    const CheckpointRows owned = interleaved(scene, comm.rank(), comm.size());
    const std::string path = dir.file("empty.h5");
    CHECK(caught([&] { write_checkpoint(path, comm, make_header(scene), owned); }) == "none");
    std::pair<CheckpointHeader, CheckpointRows> back;
    CHECK(caught([&] { back = read_checkpoint(path, comm); }) == "none");
    CHECK(back.second.nodes.gid.empty());
    CHECK(back.second.nodes.column("x").size() == 0);
    CHECK(back.second.joints.column("history").components == 3);
    CHECK(back.first.n_tets == 4321);
  }
}

TEST_CASE("checkpoint: a file written by one rank reads the same on all ranks",
          "[mpi][checkpoint]") {
  const Communicator world = Communicator::world();
  INFO("rank " << world.rank() << " of " << world.size());
  const SharedTempDir dir(world, "checkpoint");
  const FileScene scene;
  const CheckpointHeader header = make_header(scene);
  const std::string by_one = dir.file("by_one.h5"), by_all = dir.file("by_all.h5");

  // Rank 0 alone, on a communicator of its own, owning everything.
  MPI_Comm solo = MPI_COMM_NULL;
  MPI_Comm_split(MPI_COMM_WORLD, world.rank() == 0 ? 0 : MPI_UNDEFINED, 0, &solo);
  if (world.rank() == 0) {
    const Communicator one(solo);
    CHECK(one.size() == 1);
    CHECK(caught([&] { write_checkpoint(by_one, one, header, interleaved(scene, 0, 1)); }) ==
          "none");
    MPI_Comm_free(&solo);
  }
  world.barrier();
  // All ranks, each owning its interleaved share (friction pairs differ: 3 per writer).
  CHECK(caught([&] {
          write_checkpoint(by_all, world, header, interleaved(scene, world.rank(), world.size()));
        }) == "none");

  std::pair<CheckpointHeader, CheckpointRows> one_writer, all_writers;
  CHECK(caught([&] { one_writer = read_checkpoint(by_one, world); }) == "none");
  CHECK(caught([&] { all_writers = read_checkpoint(by_all, world); }) == "none");
  CHECK(one_writer.first.ranks == 1);
  CHECK(all_writers.first.ranks == world.size());
  check_header_equal(one_writer.first, header, 1);
  check_rows_equal(one_writer.second, expected_rows(scene, 1));
  // Node and joint rows do not depend on how many ranks wrote them.
  CheckpointRows without_friction = all_writers.second;
  without_friction.pair_a = one_writer.second.pair_a;
  without_friction.pair_b = one_writer.second.pair_b;
  without_friction.pair_columns = one_writer.second.pair_columns;
  check_rows_equal(without_friction, one_writer.second);
}

TEST_CASE("checkpoint: written through a temporary name, other files untouched",
          "[mpi][checkpoint]") {
  const Communicator comm = Communicator::world();
  INFO("rank " << comm.rank() << " of " << comm.size());
  const SharedTempDir dir(comm, "checkpoint");
  FileScene scene;
  scene.n_nodes = 60;
  scene.n_joints = 20;
  CheckpointHeader header = make_header(scene);
  const CheckpointRows owned = interleaved(scene, comm.rank(), comm.size());
  const std::string older = dir.file("step_100.h5"), newer = dir.file("step_200.h5");

  CHECK(caught([&] { write_checkpoint(older, comm, header, owned); }) == "none");
  const std::string older_bytes = comm.broadcast(file_bytes(older), 0);
  CHECK(!older_bytes.empty());

  header.integers[0].second = 200;
  CHECK(caught([&] { write_checkpoint(newer, comm, header, owned); }) == "none");
  CHECK(fs::exists(newer));
  CHECK_FALSE(fs::exists(newer + ".tmp"));
  CHECK_FALSE(fs::exists(older + ".tmp"));
  CHECK(file_bytes(older) == older_bytes);

  // Writing the same name again replaces it whole.
  header.integers[0].second = 300;
  CHECK(caught([&] { write_checkpoint(newer, comm, header, owned); }) == "none");
  std::pair<CheckpointHeader, CheckpointRows> back;
  CHECK(caught([&] { back = read_checkpoint(newer, comm); }) == "none");
  CHECK(back.first.integers.at(0) == std::make_pair(std::string("step"), std::int64_t{300}));

  // A write that fails (the temporary name is taken by a directory) leaves the file at the final
  // name as it was.
  const std::string newer_bytes = comm.broadcast(file_bytes(newer), 0);
  if (comm.is_root()) fs::create_directory(newer + ".tmp");
  comm.barrier();
  header.integers[0].second = 400;
  const std::string result = caught([&] { write_checkpoint(newer, comm, header, owned); });
  CHECK(same_on_all_ranks(comm, result));
  CHECK(result.rfind("io:", 0) == 0);  // a write failure is I/O, not bad input
  CHECK(result.find(newer) != std::string::npos);
  comm.barrier();
  CHECK(file_bytes(newer) == newer_bytes);
  CHECK(caught([&] { back = read_checkpoint(newer, comm); }) == "none");
  CHECK(back.first.integers.at(0).second == 300);
}
