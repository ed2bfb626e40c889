// Model files (`fdem prepare`, parallel/model_file): the file holds exactly the nodes and tets of
// the .msh in file order; read back with any physical selection it gives read_gmsh's mesh, for any
// block and window size of the streaming pass; a bad .msh is refused with read_gmsh's message; a
// damaged or foreign model file is refused.
#include <hdf5.h>

#include <array>
#include <catch2/catch.hpp>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/gmsh_reader.hpp"
#include "parallel/model_file.hpp"

namespace {

namespace fs = std::filesystem;

std::string data_file(const std::string& name) {
  return std::string(FDEM_TEST_DATA) + "/gmsh/" + name;
}

std::string scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "fdem_test_model_file";
  fs::create_directories(dir);
  return (dir / name).string();
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const fdem::InputError& e) {
    return e.what();
  }
  return "";
}

void replace_all(std::string& text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at))
    text.replace(at, from.size(), to), at += to.size();
}

void require_same(const fdem::GmshMesh& a, const fdem::GmshMesh& b) {
  CHECK(a.coords == b.coords);  // bit for bit (== on doubles; no NaN in meshes)
  CHECK(a.node_tags == b.node_tags);
  CHECK(a.tets == b.tets);
  CHECK(a.tet_tags == b.tet_tags);
  CHECK(a.tet_physical == b.tet_physical);
  CHECK(a.physical_names == b.physical_names);
}

const char* const good_files[] = {"single_tet.msh",
                                  "extra_sections.msh",
                                  "sparse_tags.msh",
                                  "cube_two_volumes_ascii.msh",
                                  "cube_two_volumes_binary.msh",
                                  "brazilian_disc_coarse.msh",
                                  "two_blocks.msh",
                                  "two_blocks_binary.msh"};

}  // namespace

TEST_CASE("prepare: the model file holds every node and tet of the .msh in file order",
          "[parallel][model_file]") {
  SECTION("single tet: the unused node too, the triangle not") {
    const std::string h5 = scratch("single_tet.h5");
    const fdem::PrepareReport report = fdem::prepare_model_file(data_file("single_tet.msh"), h5);
    CHECK(report.nodes == 5);
    CHECK(report.tets == 1);
    const fdem::ModelFileContent c = fdem::read_model_file_content(h5);
    CHECK(c.header.version == fdem::model_file_version);
    CHECK(c.header.n_nodes == 5);
    CHECK(c.header.n_tets == 1);
    CHECK(c.header.source == data_file("single_tet.msh"));
    CHECK(c.header.source_bytes ==
          static_cast<std::int64_t>(fs::file_size(data_file("single_tet.msh"))));
    CHECK(c.node_tag == std::vector<std::int64_t>{5, 1, 2, 3, 4});
    CHECK(c.node_x == std::vector<double>{9, 9, 9, 0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, 4});
    CHECK(c.tet_nodes == std::vector<std::int64_t>{1, 2, 3, 4});
    CHECK(c.tet_tag == std::vector<std::int64_t>{2});
    CHECK(c.tet_entity == std::vector<std::int32_t>{9});
    CHECK(c.tet_physical == std::vector<std::int32_t>{3});
    CHECK(c.tables.names_3d == std::map<std::string, int>{{"rock", 3}});
    CHECK(c.tables.volume_physicals == std::map<int, std::vector<int>>{{9, {3}}});
  }
  SECTION("sparse tags above 2^32, two volumes in three groups, small blocks") {
    const std::string h5 = scratch("sparse_tags.h5");
    fdem::prepare_model_file(data_file("sparse_tags.msh"), h5, {1, 64});
    const fdem::ModelFileContent c = fdem::read_model_file_content(h5);
    CHECK(c.node_tag == std::vector<std::int64_t>{7, 500000000000, 1000, 42, 3});
    CHECK(c.node_x == std::vector<double>{1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, -1});
    CHECK(c.tet_nodes == std::vector<std::int64_t>{2, 0, 1, 3, 2, 1, 0, 4});
    CHECK(c.tet_tag == std::vector<std::int64_t>{900, 77});
    CHECK(c.tet_entity == std::vector<std::int32_t>{1, 2});
    CHECK(c.tet_physical == std::vector<std::int32_t>{11, 12});
    CHECK(c.tables.volume_physicals ==
          std::map<int, std::vector<int>>{{1, {11, 13}}, {2, {12, 13}}});
    CHECK(c.tables.names_3d ==
          std::map<std::string, int>{{"upper", 11}, {"lower", 12}, {"whole body", 13}});
  }
}

TEST_CASE("model file read back = read_gmsh, for every selection, block and window size",
          "[parallel][model_file]") {
  const std::vector<fdem::PrepareOptions> options = {{}, {1, 64}, {7, 100}, {1000, 333}};
  for (const char* name : good_files) {
    const std::string msh = data_file(name);
    std::vector<std::string> selections = {""};
    for (const auto& [group, tag] : fdem::read_gmsh(msh).physical_names) {
      selections.push_back(group);
      selections.push_back(std::to_string(tag));
    }
    for (std::size_t o = 0; o < options.size(); ++o) {
      INFO(name << ", block rows " << options[o].block_rows << ", window "
                << options[o].window_bytes);
      const std::string h5 = scratch(std::string(name) + std::to_string(o) + ".h5");
      fdem::prepare_model_file(msh, h5, options[o]);
      for (const std::string& physical : selections) {
        INFO("physical '" << physical << "'");
        require_same(fdem::read_model_file(h5, physical), fdem::read_gmsh(msh, physical));
      }
    }
  }
}

TEST_CASE("prepare refuses a bad .msh with read_gmsh's message (file, line or byte, what)",
          "[parallel][model_file]") {
  for (const char* name :
       {"cube_truncated_ascii.msh", "cube_truncated_binary.msh", "binary_other_endian.msh",
        "box_coarse_v22.msh", "box_coarse_v40.msh", "box_surface_only.msh", "not_a_mesh.stl",
        "unknown_node.msh", "second_order_tet.msh", "tet_no_groups.msh", "no_such_mesh.msh"}) {
    INFO(name);
    const std::string msh = data_file(name);
    const std::string expected = error_of([&] { fdem::read_gmsh(msh); });
    for (std::size_t window : {std::size_t{64}, std::size_t{1} << 20}) {
      const std::string found = error_of([&] {
        fdem::prepare_model_file(msh, scratch("bad.h5"), {3, window});
      });
      if (expected.empty()) {  // a good file (tet_no_groups)
        CHECK(found.empty());
        continue;
      }
      CHECK(found == expected);
    }
    CHECK(!fs::exists(scratch("bad.h5.tmp")));
    CHECK(!fs::exists(scratch("bad.h5.tets.tmp")));
  }
  // Volume elements fdem cannot use, a group without tets: refused when selected, as read_gmsh
  // refuses them, with the model file named first.
  for (const auto& [name, physical] : std::vector<std::pair<std::string, std::string>>{
           {"empty_group.msh", "void"}, {"sparse_tags.msh", "nope"}}) {
    INFO(name);
    const std::string msh = data_file(name), h5 = scratch("selection.h5");
    fdem::prepare_model_file(msh, h5);
    std::string expected = error_of([&] { fdem::read_gmsh(msh, physical); });
    replace_all(expected, "Gmsh file '" + msh + "'",
                "model file '" + h5 + "' (prepared from '" + msh + "')");
    CHECK(!expected.empty());
    CHECK(error_of([&] { fdem::read_model_file(h5, physical); }) == expected);
  }
}

TEST_CASE("a damaged or foreign model file is refused", "[parallel][model_file]") {
  const std::string h5 = scratch("damaged.h5");
  const auto prepare = [&] { fdem::prepare_model_file(data_file("two_blocks.msh"), h5); };
  const auto contains = [](const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
  };
  SECTION("one node index changed in the file") {
    prepare();
    const hid_t file = H5Fopen(h5.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    const hid_t dataset = H5Dopen2(file, "/tets/nodes", H5P_DEFAULT);
    const hid_t space = H5Dget_space(dataset);
    const std::array<hsize_t, 2> start{100, 2}, count{1, 1};
    H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
    const hsize_t one = 1;
    const hid_t memory = H5Screate_simple(1, &one, nullptr);
    const std::int64_t other = 3;
    REQUIRE(H5Dwrite(dataset, H5T_NATIVE_INT64, memory, space, H5P_DEFAULT, &other) >= 0);
    H5Sclose(memory);
    H5Sclose(space);
    H5Dclose(dataset);
    H5Fclose(file);
    const std::string message = error_of([&] { fdem::read_model_file(h5); });
    CHECK(contains(message, "model file '" + h5 + "'"));
    CHECK(contains(message, "dataset /tets/nodes does not match its checksum"));
  }
  SECTION("truncated") {
    prepare();
    fs::resize_file(h5, fs::file_size(h5) - 1000);
    const std::string message = error_of([&] { fdem::read_model_file(h5); });
    CHECK(contains(message, "model file '" + h5 + "'"));
    CHECK(contains(message, "shorter than its datasets"));
  }
  SECTION("not HDF5, not a model file") {
    CHECK(contains(error_of([&] { fdem::read_model_file(data_file("two_blocks.msh")); }),
                   "is not an HDF5 file, so not an fdem model file"));
    const hid_t file = H5Fcreate(h5.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    H5Fclose(file);
    CHECK(contains(error_of([&] { fdem::read_model_file(h5); }), "not an fdem model file"));
    CHECK(fdem::is_hdf5_file(h5));
    CHECK(!fdem::is_hdf5_file(data_file("two_blocks.msh")));
  }
}
