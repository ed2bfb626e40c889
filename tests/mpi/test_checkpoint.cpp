// Checkpoint files on 1–4 ranks: collective write of owned rows into one HDF5 file, read back
// everywhere bit-exactly, any writer count, errors on every rank, temp file + rename.
// Only CHECK here (no REQUIRE): a rank leaving a test case early would skip its collectives.
#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "core/error.hpp"
#include "parallel/checkpoint.hpp"
#include "parallel/checkpoint_fields.hpp"
#include "parallel/checkpoint_seal.hpp"
#include "parallel/communicator.hpp"

using namespace fdem;
namespace fs = std::filesystem;

namespace {

// A directory under /tmp that rank 0 creates and removes; every rank gets its name.
class SharedTempDir {
 public:
  explicit SharedTempDir(const Communicator& comm) : comm_(comm) {
    std::string name;
    if (comm.is_root()) {
      static int counter = 0;
      name = (fs::temp_directory_path() / ("fdem-checkpoint-test-" + std::to_string(::getpid()) +
                                           "-" + std::to_string(counter++)))
                 .string();
      fs::remove_all(name);
      fs::create_directories(name);
    }
    path_ = comm.broadcast(name, 0);
  }
  ~SharedTempDir() {
    comm_.barrier();
    if (comm_.is_root()) {
      std::error_code ignored;
      fs::remove_all(path_, ignored);
    }
  }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  Communicator comm_;
  std::string path_;
};

// Distinct values with special cases (signed zero, infinity, NaN, subnormal) so that the
// comparison really is bit for bit.
double node_value(int field, GlobalId gid, int component) {
  if (gid == 3 && component == 0) return -0.0;
  if (gid == 5 && component == 1) return std::numeric_limits<double>::infinity();
  if (gid == 7 && component == 2) return std::numeric_limits<double>::quiet_NaN();
  if (gid == 11 && component == 0) return std::numeric_limits<double>::denorm_min() * (field + 1);
  return std::sin(1.0 + 0.37 * static_cast<double>(gid) + 0.11 * component + 10.0 * field) *
         std::pow(10.0, field - 2);
}
std::uint8_t history_byte(GlobalId gid, std::size_t b) {
  return static_cast<std::uint8_t>((gid * 31 + static_cast<GlobalId>(b) * 7 + 1) & 0xff);
}

struct FileScene {
  std::int64_t n_nodes = 1000, n_joints = 300;
  std::size_t history_bytes = 12;
  int friction_per_writer = 3;
};

// The header every rank passes (the same everywhere).
CheckpointHeader make_header(const FileScene& scene) {
  CheckpointHeader h;
  h.n_nodes = scene.n_nodes;
  h.n_tets = 4321;
  h.n_joints = scene.n_joints;
  h.reference_hash = 0xfedcba9876543210ULL;
  h.doubles = {{"time", 1.25e-3}, {"dt", 1e-7}, {"energy_in", -3.5e4}, {"alpha", 0.1}};
  h.integers = {
      {"step", 12345}, {"detections", -7}, {"largest", std::numeric_limits<std::int64_t>::max()}};
  return h;
}

// One row of `columns` (the k-th column's values from pattern k: doubles with the special cases,
// integers and bytes from the gid).
void add_row(std::vector<CheckpointColumn>& columns, GlobalId g) {
  for (std::size_t k = 0; k < columns.size(); ++k) {
    CheckpointColumn& column = columns[k];
    const int field = static_cast<int>(k);
    for (std::size_t i = 0; i < column.components; ++i)
      std::visit(
          [&](auto& values) {
            using T = typename std::decay_t<decltype(values)>::value_type;
            if constexpr (std::is_floating_point_v<T>)
              values.push_back(node_value(field, g, static_cast<int>(i)));
            else
              values.push_back(static_cast<T>(history_byte(g + 1000 * field, i)));
          },
          column.values);
  }
}
void add_node(CheckpointRows& rows, GlobalId g) {
  rows.nodes.gid.push_back(g);
  add_row(rows.nodes.columns, g);
}
void add_joint(CheckpointRows& rows, GlobalId j) {
  rows.joints.gid.push_back(j);
  add_row(rows.joints.columns, j);
}
// Friction pairs of writer `w`: a deliberately not sorted, so the reader's sort is exercised.
void add_friction(CheckpointRows& rows, const FileScene& scene, int writer) {
  for (int k = scene.friction_per_writer - 1; k >= 0; --k) {
    const GlobalId a = 900 - 10 * writer - k, b = a + 1 + k;
    rows.pair_a.push_back(a);
    rows.pair_b.push_back(b);
    for (CheckpointColumn& column : rows.pair_columns)
      for (std::size_t c = 0; c < column.components; ++c)
        std::get<std::vector<double>>(column.values)
            .push_back(1e-6 * (a + double(c)) - 1e-7 * b + double(column.components));
  }
}
// The columns fdem writes (parallel/checkpoint_fields), with joint records of `history_bytes`.
CheckpointRows empty_rows(const FileScene& scene) {
  return checkpoint_layout(scene.history_bytes);
}

// What `writer` of `writers` owns: nodes interleaved (gid % writers), joints by another pattern,
// `owner_of` may leave some writers without rows.
template <class NodeOwner, class JointOwner>
CheckpointRows make_owned(const FileScene& scene, int writer, NodeOwner node_owner,
                          JointOwner joint_owner) {
  CheckpointRows rows = empty_rows(scene);
  // Descending gid order, so the writer's own sort to file positions is exercised.
  for (GlobalId g = scene.n_nodes - 1; g >= 0; --g)
    if (node_owner(g) == writer) add_node(rows, g);
  for (GlobalId j = 0; j < scene.n_joints; ++j)
    if (joint_owner(j) == writer) add_joint(rows, j);
  add_friction(rows, scene, writer);
  return rows;
}
CheckpointRows interleaved(const FileScene& scene, int writer, int writers) {
  return make_owned(
      scene, writer, [&](GlobalId g) { return static_cast<int>(g % writers); },
      [&](GlobalId j) { return static_cast<int>((j / 7) % writers); });
}

// Everything, sorted as read_checkpoint returns it, for `writers` writers with friction.
CheckpointRows expected_rows(const FileScene& scene, int writers) {
  CheckpointRows all = empty_rows(scene);
  for (GlobalId g = 0; g < scene.n_nodes; ++g) add_node(all, g);
  for (GlobalId j = 0; j < scene.n_joints; ++j) add_joint(all, j);
  CheckpointRows pairs = empty_rows(scene);
  for (int w = 0; w < writers; ++w) add_friction(pairs, scene, w);
  std::vector<std::size_t> order(pairs.pair_a.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
    return std::make_pair(pairs.pair_a[i], pairs.pair_b[i]) <
           std::make_pair(pairs.pair_a[j], pairs.pair_b[j]);
  });
  for (std::size_t i : order) {
    all.pair_a.push_back(pairs.pair_a[i]);
    all.pair_b.push_back(pairs.pair_b[i]);
    for (std::size_t k = 0; k < pairs.pair_columns.size(); ++k) {
      const std::size_t width = pairs.pair_columns[k].components;
      const auto& from = std::get<std::vector<double>>(pairs.pair_columns[k].values);
      auto& to = std::get<std::vector<double>>(all.pair_columns[k].values);
      to.insert(to.end(), from.begin() + static_cast<std::ptrdiff_t>(i * width),
                from.begin() + static_cast<std::ptrdiff_t>((i + 1) * width));
    }
  }
  return all;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void check_columns_equal(const std::vector<CheckpointColumn>& got,
                         const std::vector<CheckpointColumn>& want) {
  CHECK(got.size() == want.size());
  for (std::size_t k = 0; k < std::min(got.size(), want.size()); ++k) {
    INFO("column " << want[k].name);
    CHECK(got[k].name == want[k].name);
    CHECK(got[k].components == want[k].components);
    CHECK(got[k].type() == want[k].type());
    if (got[k].type() == want[k].type())
      std::visit(
          [&](const auto& values) {
            CHECK(same_bits(values, std::get<std::decay_t<decltype(values)>>(want[k].values)));
          },
          got[k].values);
  }
}

void check_rows_equal(const CheckpointRows& got, const CheckpointRows& want) {
  CHECK(got.nodes.gid == want.nodes.gid);
  CHECK(std::is_sorted(got.nodes.gid.begin(), got.nodes.gid.end()));
  check_columns_equal(got.nodes.columns, want.nodes.columns);
  CHECK(got.joints.gid == want.joints.gid);
  CHECK(std::is_sorted(got.joints.gid.begin(), got.joints.gid.end()));
  check_columns_equal(got.joints.columns, want.joints.columns);
  CHECK(got.pair_a == want.pair_a);
  CHECK(got.pair_b == want.pair_b);
  check_columns_equal(got.pair_columns, want.pair_columns);
}

void check_header_equal(const CheckpointHeader& got, const CheckpointHeader& want, int ranks) {
  CHECK(got.n_nodes == want.n_nodes);
  CHECK(got.n_tets == want.n_tets);
  CHECK(got.n_joints == want.n_joints);
  CHECK(got.reference_hash == want.reference_hash);
  CHECK(got.ranks == ranks);
  CHECK(got.integers == want.integers);
  CHECK(got.doubles.size() == want.doubles.size());
  for (std::size_t i = 0; i < std::min(got.doubles.size(), want.doubles.size()); ++i) {
    CHECK(got.doubles[i].first == want.doubles[i].first);
    CHECK(std::memcmp(&got.doubles[i].second, &want.doubles[i].second, sizeof(double)) == 0);
  }
}

// Runs `body` and returns what this rank caught: "input:<message>", "internal:<message>",
// "io:<message>", "other" or "none".
template <class Body>
std::string caught(Body&& body) {
  try {
    body();
    return "none";
  } catch (const CollectiveInputError& e) {
    return std::string("input:") + e.what();
  } catch (const CollectiveInternalError& e) {
    return std::string("internal:") + e.what();
  } catch (const CollectiveIoError& e) {
    return std::string("io:") + e.what();
  } catch (...) {
    return "other";
  }
}

// Writes the seal of an HDF5 file edited after fdem wrote it (every dataset's raw data found).
void reseal(const std::string& path) {
  std::vector<FileRegion> regions;
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  for (const char* group : {"/nodes", "/joints", "/friction"})
    for (const char* name : {"gid", "x", "v", "x_at_detection", "prescribed_velocity", "broken",
                             "mode", "history", "a", "b", "spring", "stiffness"}) {
      const std::string full = std::string(group) + "/" + name;
      if (H5Lexists(file, group, H5P_DEFAULT) <= 0 ||
          H5Lexists(file, full.c_str(), H5P_DEFAULT) <= 0)
        continue;
      const hid_t set = H5Dopen2(file, full.c_str(), H5P_DEFAULT);
      const haddr_t offset = H5Dget_offset(set);
      if (offset != HADDR_UNDEF) regions.push_back({offset, H5Dget_storage_size(set)});
      H5Dclose(set);
    }
  H5Fclose(file);
  write_checkpoint_seal(path, regions);
}

bool same_on_all_ranks(const Communicator& comm, const std::string& text) {
  return comm.sum<std::int32_t>(comm.broadcast(text, 0) == text ? 0 : 1) == 0;
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

TEST_CASE("checkpoint: interleaved rows of every rank round-trip bit-exactly",
          "[mpi][checkpoint]") {
  const Communicator comm = Communicator::world();
  INFO("rank " << comm.rank() << " of " << comm.size());
  const SharedTempDir dir(comm);
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
  const SharedTempDir dir(comm);
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
  const SharedTempDir dir(world);
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

TEST_CASE("checkpoint: unreadable files are an InputError on every rank naming the file",
          "[mpi][checkpoint][failure]") {
  const Communicator comm = Communicator::world();
  INFO("rank " << comm.rank() << " of " << comm.size());
  const SharedTempDir dir(comm);
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

TEST_CASE("checkpoint: written through a temporary name, other files untouched",
          "[mpi][checkpoint]") {
  const Communicator comm = Communicator::world();
  INFO("rank " << comm.rank() << " of " << comm.size());
  const SharedTempDir dir(comm);
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
