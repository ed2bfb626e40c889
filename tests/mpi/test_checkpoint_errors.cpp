// Checkpoint files that cannot be read (missing, not HDF5, altered, truncated, of another
// layout): an InputError on every rank, naming the file.
// Only CHECK here (no REQUIRE): a rank leaving a test case early would skip its collectives.
#include <catch2/catch.hpp>

#include "checkpoint_test_rows.hpp"

using namespace fdem;
using namespace fdem::checkpoint_test;

TEST_CASE("checkpoint: unreadable files are an InputError on every rank naming the file",
          "[mpi][checkpoint][failure]") {
  const Communicator comm = Communicator::world();
  INFO("rank " << comm.rank() << " of " << comm.size());
  const SharedTempDir dir(comm, "checkpoint");
  FileScene scene;
  scene.n_nodes = 40;
  scene.n_joints = 10;
  const CheckpointHeader header = make_header(scene);
  const CheckpointRows owned = interleaved(scene, comm.rank(), comm.size());

  auto read_error = [&](const std::string& path) {
    const std::string result = caught([&] { read_checkpoint(path, comm); });
    CHECK(same_on_all_ranks(comm, result));
    CHECK(result.rfind("input:", 0) == 0);
    CHECK(result.find("'" + path + "'") != std::string::npos);
    return result;
  };
  // A good checkpoint, then altered by rank 0 with serial HDF5.
  auto good_copy = [&](const std::string& name) {
    const std::string path = dir.file(name);
    CHECK(caught([&] { write_checkpoint(path, comm, header, owned); }) == "none");
    return path;
  };
  // The edit changes the HDF5 metadata: the file is sealed again afterwards (as a tool that
  // rewrote it would), so that the reader's own checks are what the section tests.
  auto alter = [&](const std::string& path, auto&& edit) {
    if (comm.is_root()) {
      const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
      CHECK(file >= 0);
      edit(file);
      CHECK(H5Fclose(file) >= 0);
      reseal(path);
    }
    comm.barrier();
  };

  SECTION("missing file") {
    const std::string message = read_error(dir.file("nowhere.h5"));
    CHECK(message.find("does not exist") != std::string::npos);
  }
  SECTION("a plain text file") {
    const std::string path = dir.file("notes.txt");
    if (comm.is_root()) std::ofstream(path) << "time = 1.0\nstep = 10\n";
    comm.barrier();
    const std::string message = read_error(path);
    CHECK(message.find("not an HDF5 file") != std::string::npos);
  }
  SECTION("an HDF5 file that is not an fdem checkpoint") {
    const std::string path = dir.file("other.h5");
    if (comm.is_root()) {
      const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
      CHECK(file >= 0);
      CHECK(H5Fclose(file) >= 0);
    }
    comm.barrier();
    const std::string message = read_error(path);
    CHECK(message.find("not an fdem checkpoint") != std::string::npos);
  }
  SECTION("a dataset with rows missing") {
    const std::string path = good_copy("short_x.h5");
    alter(path, [](hid_t file) {
      CHECK(H5Ldelete(file, "/nodes/x", H5P_DEFAULT) >= 0);
      const hsize_t dims[2] = {39, 3};
      const hid_t space = H5Screate_simple(2, dims, nullptr);
      const hid_t dataset = H5Dcreate2(file, "/nodes/x", H5T_IEEE_F64LE, space, H5P_DEFAULT,
                                       H5P_DEFAULT, H5P_DEFAULT);
      CHECK(dataset >= 0);
      H5Dclose(dataset);
      H5Sclose(space);
    });
    const std::string message = read_error(path);
    CHECK(message.find("/nodes/x") != std::string::npos);
    CHECK(message.find("39 x 3") != std::string::npos);
    CHECK(message.find("40 x 3") != std::string::npos);
  }
  SECTION("a missing dataset") {
    const std::string path = good_copy("no_damage.h5");
    alter(path, [](hid_t file) { CHECK(H5Ldelete(file, "/joints/mode", H5P_DEFAULT) >= 0); });
    const std::string message = read_error(path);
    CHECK(message.find("/joints/mode") != std::string::npos);
  }
  SECTION("another format version") {
    const std::string path = good_copy("version2.h5");
    alter(path, [](hid_t file) {
      const hid_t attr = H5Aopen(file, "version", H5P_DEFAULT);
      const std::int32_t two = 2;  // fixed datasets, before the field tables
      CHECK(H5Awrite(attr, H5T_NATIVE_INT32, &two) >= 0);
      H5Aclose(attr);
    });
    const std::string message = read_error(path);
    CHECK(message.find("format version 2; this fdem reads version 4") != std::string::npos);
    CHECK(message.find("older fdem") != std::string::npos);
  }
  SECTION("datasets other than the ones this build restores") {
    const std::string path = good_copy("other_fields.h5");
    // A reader whose joint records are 16 bytes, where the file's are 12.
    FileScene other = scene;
    other.history_bytes = 16;
    const CheckpointRows layout = empty_rows(other);
    const std::string result = caught([&] { read_checkpoint(path, comm, nullptr, {}, &layout); });
    CHECK(same_on_all_ranks(comm, result));
    CHECK(result.rfind("input:", 0) == 0);
    CHECK(result.find("the file has joints/history:uint8[12] where this fdem restores "
                      "joints/history:uint8[16]") != std::string::npos);
    // The same layout as the file's reads.
    const CheckpointRows same = empty_rows(scene);
    CHECK(caught([&] { read_checkpoint(path, comm, nullptr, {}, &same); }) == "none");
  }
  // Flips bit 4 of the byte at `offset` of the file (rank 0), then waits for it.
  auto flip = [&](const std::string& path, std::uint64_t offset) {
    if (comm.is_root()) {
      std::fstream bytes(path, std::ios::in | std::ios::out | std::ios::binary);
      bytes.seekg(static_cast<std::streamoff>(offset));
      char byte = 0;
      bytes.read(&byte, 1);
      byte = static_cast<char>(byte ^ 0x10);
      bytes.seekp(static_cast<std::streamoff>(offset));
      bytes.write(&byte, 1);
      CHECK(bytes.good());
    }
    comm.barrier();
  };
  SECTION("one flipped bit in a dataset: checkpoint corrupt, naming the dataset") {
    for (const char* dataset : {"/nodes/x", "/nodes/v", "/joints/mode", "/joints/history"}) {
      const std::string path = good_copy("flipped.h5");
      haddr_t offset = HADDR_UNDEF;  // the dataset's bytes in the file (contiguous layout)
      hsize_t size = 0;
      if (comm.is_root()) {
        const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
        const hid_t set = H5Dopen2(file, dataset, H5P_DEFAULT);
        offset = H5Dget_offset(set);  // from the start of the file (userblock included)
        size = H5Dget_storage_size(set);
        H5Dclose(set);
        H5Fclose(file);
        REQUIRE(offset != HADDR_UNDEF);
        REQUIRE(size > 0);
      }
      flip(path, offset + size / 2);
      const std::string message = read_error(path);
      INFO(message);
      CHECK(message.find(std::string("checkpoint corrupt: dataset ") + dataset) !=
            std::string::npos);
    }
  }
  SECTION("one flipped bit in the HDF5 metadata or the seal: refused before HDF5 parses it") {
    for (const std::uint64_t offset :
         {checkpoint_seal_bytes + 40, checkpoint_seal_bytes + 700, std::uint64_t{30}}) {
      const std::string path = good_copy("metadata.h5");
      flip(path, offset);
      const std::string message = read_error(path);
      INFO("byte " << offset << ": " << message);
      CHECK(message.find("checkpoint corrupt: its ") != std::string::npos);
    }
  }
  SECTION("a changed run value: checkpoint corrupt (header)") {
    const std::string path = good_copy("run_value.h5");
    alter(path, [&](hid_t file) {
      const hid_t run = H5Gopen2(file, "/run", H5P_DEFAULT);
      const hid_t attr = H5Aopen(run, header.doubles.front().first.c_str(), H5P_DEFAULT);
      const double changed = header.doubles.front().second + 1.0;
      CHECK(H5Awrite(attr, H5T_NATIVE_DOUBLE, &changed) >= 0);
      H5Aclose(attr);
      H5Gclose(run);
    });
    const std::string message = read_error(path);
    CHECK(message.find("checkpoint corrupt: header") != std::string::npos);
  }
  SECTION("a file cut short") {
    const std::string path = good_copy("cut.h5");
    if (comm.is_root()) fs::resize_file(path, fs::file_size(path) / 2);
    comm.barrier();
    read_error(path);
  }
  SECTION("a write into a missing directory") {
    const std::string path = dir.file("no/such/dir/state.h5");
    const std::string result = caught([&] { write_checkpoint(path, comm, header, owned); });
    CHECK(same_on_all_ranks(comm, result));
    CHECK(result.rfind("io:", 0) == 0);  // writing: an I/O failure
    CHECK(result.find("'" + path + "'") != std::string::npos);
  }
  SECTION("rows that are not a partition are an internal error on every rank") {
    CheckpointRows twice = owned;
    if (comm.is_root()) add_node(twice, 1 % scene.n_nodes);  // gid 1 owned twice overall
    const std::string path = dir.file("bad_rows.h5");
    const std::string result = caught([&] { write_checkpoint(path, comm, header, twice); });
    CHECK(same_on_all_ranks(comm, result));
    CHECK(result.rfind("internal:", 0) == 0);
    comm.barrier();
    CHECK_FALSE(fs::exists(path));
    CHECK_FALSE(fs::exists(path + ".tmp"));
  }
}
