// Gmsh MSH 4.1 reader: exact arrays on hand-written files, ASCII/binary agreement and volume on
// Gmsh-generated meshes, physical-group filtering, and the content of every error message.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/gmsh_cursor.hpp"
#include "io/gmsh_parser.hpp"
#include "io/gmsh_reader.hpp"

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string data_file(const std::string& name) {
  return std::string(FDEM_TEST_DATA) + "/gmsh/" + name;
}

// Signed volume of tet t: det[b-a, c-a, d-a] / 6 (m^3).
double tet_volume(const fdem::GmshMesh& mesh, std::size_t t) {
  std::array<std::array<double, 3>, 4> p{};
  for (int k = 0; k < 4; ++k) {
    const std::size_t node = static_cast<std::size_t>(mesh.tets[4 * t + k]);
    for (int d = 0; d < 3; ++d) p[k][d] = mesh.coords[3 * node + d];
  }
  double e[3][3];
  for (int k = 0; k < 3; ++k) {
    for (int d = 0; d < 3; ++d) e[k][d] = p[k + 1][d] - p[0][d];
  }
  const double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                     e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                     e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
  return det / 6.0;
}

double total_volume(const fdem::GmshMesh& mesh) {
  double sum = 0.0;
  for (std::size_t t = 0; t < mesh.num_tets(); ++t) sum += tet_volume(mesh, t);
  return sum;
}

// The message of the InputError that reading throws ("" if none is thrown).
std::string error_of(const std::string& path, const std::string& physical = "") {
  try {
    fdem::read_gmsh(path, physical);
  } catch (const fdem::InputError& error) {
    return error.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("single tet: exact arrays, unused node dropped, triangle skipped", "[io][gmsh]") {
  const fdem::GmshMesh mesh = fdem::read_gmsh(data_file("single_tet.msh"));
  CHECK(mesh.node_tags == std::vector<std::int64_t>{1, 2, 3, 4});
  CHECK(mesh.coords == std::vector<double>{0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, 4});
  CHECK(mesh.tets == std::vector<std::int32_t>{0, 1, 2, 3});
  CHECK(mesh.tet_tags == std::vector<std::int64_t>{2});
  CHECK(mesh.tet_physical == std::vector<int>{3});
  CHECK(mesh.physical_names == std::map<std::string, int>{{"rock", 3}});
  // Legs 2, 3, 4 m: volume 2*3*4/6 = 4 m^3, exact in floating point.
  CHECK(tet_volume(mesh, 0) == 4.0);
}

TEST_CASE("unknown sections ($Comments, $Periodic, $NodeData) and blank lines are skipped",
          "[io][gmsh]") {
  const fdem::GmshMesh plain = fdem::read_gmsh(data_file("single_tet.msh"));
  const fdem::GmshMesh extra = fdem::read_gmsh(data_file("extra_sections.msh"));
  CHECK(extra.coords == plain.coords);
  CHECK(extra.node_tags == plain.node_tags);
  CHECK(extra.tets == plain.tets);
  CHECK(extra.tet_tags == plain.tet_tags);
  CHECK(extra.tet_physical == plain.tet_physical);
  CHECK(extra.physical_names == plain.physical_names);
}

TEST_CASE("sparse node tags, parametric block, groups sharing a volume", "[io][gmsh]") {
  const std::string path = data_file("sparse_tags.msh");
  const fdem::GmshMesh mesh = fdem::read_gmsh(path);
  // File order of the nodes, which all are used; one tag needs more than 32 bits.
  CHECK(mesh.node_tags == std::vector<std::int64_t>{7, 500000000000, 1000, 42, 3});
  CHECK(mesh.coords == std::vector<double>{1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, -1});
  CHECK(mesh.tets == std::vector<std::int32_t>{2, 0, 1, 3, 2, 1, 0, 4});
  CHECK(mesh.tet_tags == std::vector<std::int64_t>{900, 77});
  CHECK(mesh.tet_physical == std::vector<int>{11, 12});  // first group listed for the entity
  CHECK(mesh.physical_names ==
        std::map<std::string, int>{{"upper", 11}, {"lower", 12}, {"whole body", 13}});
  CHECK(tet_volume(mesh, 0) == Approx(1.0 / 6.0).epsilon(1e-15));
  CHECK(tet_volume(mesh, 1) == Approx(1.0 / 6.0).epsilon(1e-15));

  SECTION("a group with a space in its name keeps both volumes and reports its own tag") {
    const fdem::GmshMesh whole = fdem::read_gmsh(path, "whole body");
    CHECK(whole.tets == mesh.tets);
    CHECK(whole.tet_physical == std::vector<int>{13, 13});
  }
  SECTION("a group given by number keeps only its volume and only that volume's nodes") {
    const fdem::GmshMesh lower = fdem::read_gmsh(path, "12");
    CHECK(lower.tet_tags == std::vector<std::int64_t>{77});
    CHECK(lower.node_tags == std::vector<std::int64_t>{7, 500000000000, 1000, 3});
    CHECK(lower.tets == std::vector<std::int32_t>{2, 1, 0, 3});
    CHECK(lower.tet_physical == std::vector<int>{12});
  }
}

// Node tags as the streaming parse (fdem prepare) hands them over, read through a 64-byte window.
struct TagList : fdem::GmshSink {
  std::vector<std::int64_t> tags, tet_nodes;
  void node_tag(std::int64_t, std::int64_t tag) override { tags.push_back(tag); }
  void node_coords(std::int64_t, const double (&)[3]) override {}
  void tet(std::int64_t, int, const std::int64_t (&nodes)[4]) override {
    tet_nodes.insert(tet_nodes.end(), nodes, nodes + 4);
  }
};

TEST_CASE("node and element tags at the int64 limit (whole-file and streamed parse)",
          "[io][gmsh]") {
  // A run of node tags ending at 2^63 - 1: its end (first + count) is not representable.
  const std::string path = data_file("tags_at_int64_limit.msh");
  const fdem::GmshMesh mesh = fdem::read_gmsh(path);
  const std::int64_t top = INT64_MAX;
  CHECK(mesh.node_tags == std::vector<std::int64_t>{top - 3, top - 2, top - 1, top});
  CHECK(mesh.tets == std::vector<std::int32_t>{0, 1, 2, 3});
  CHECK(tet_volume(mesh, 0) == 4.0);

  fdem::gmsh::Cursor window(path, 64);
  TagList streamed;
  const auto index = fdem::make_run_index();
  const fdem::GmshTables tables = fdem::parse_gmsh_sections(window, path, *index, streamed);
  CHECK(tables.n_tets == 1);
  CHECK(streamed.tags == mesh.node_tags);
  CHECK(streamed.tet_nodes == std::vector<std::int64_t>{0, 1, 2, 3});
}

TEST_CASE("cube from Gmsh: binary and ASCII MSH 4.1 give identical arrays", "[io][gmsh]") {
  const fdem::GmshMesh ascii = fdem::read_gmsh(data_file("cube_two_volumes_ascii.msh"));
  const fdem::GmshMesh binary = fdem::read_gmsh(data_file("cube_two_volumes_binary.msh"));
  // Gmsh prints ASCII doubles with 16 significant digits: coordinates (<= 1 m) agree to 1e-15 m.
  REQUIRE(binary.coords.size() == ascii.coords.size());
  double max_difference = 0.0;
  for (std::size_t i = 0; i < ascii.coords.size(); ++i) {
    max_difference = std::max(max_difference, std::abs(binary.coords[i] - ascii.coords[i]));
  }
  CHECK(max_difference <= 1e-15);
  CHECK(binary.node_tags == ascii.node_tags);
  CHECK(binary.tets == ascii.tets);
  CHECK(binary.tet_tags == ascii.tet_tags);
  CHECK(binary.tet_physical == ascii.tet_physical);
  CHECK(binary.physical_names == ascii.physical_names);
}

TEST_CASE("cube from Gmsh: counts, bounds and total volume", "[io][gmsh]") {
  for (const char* name : {"cube_two_volumes_ascii.msh", "cube_two_volumes_binary.msh"}) {
    INFO(name);
    const fdem::GmshMesh mesh = fdem::read_gmsh(data_file(name));
    CHECK(mesh.num_nodes() == 92);
    CHECK(mesh.num_tets() == 250);  // 250 tets (and 28 skipped triangles) in the file
    CHECK(mesh.coords.size() == 3 * mesh.num_nodes());
    CHECK(mesh.tets.size() == 4 * mesh.num_tets());
    CHECK(mesh.tet_physical.size() == mesh.num_tets());
    CHECK(mesh.physical_names == std::map<std::string, int>{{"left", 1}, {"right", 2}});
    for (double x : mesh.coords) {
      CHECK(x >= 0.0);
      CHECK(x <= 1.0);
    }
    for (std::int32_t index : mesh.tets) {
      CHECK(index >= 0);
      CHECK(index < static_cast<std::int32_t>(mesh.num_nodes()));
    }
    // Sum of signed volumes = box volume 1 m^3 (tets tile the box; rounding only).
    CHECK(std::abs(total_volume(mesh) - 1.0) <= 1e-12);
  }
}

TEST_CASE("cube from Gmsh: filtering by physical volume", "[io][gmsh]") {
  const std::string path = data_file("cube_two_volumes_ascii.msh");
  const fdem::GmshMesh all = fdem::read_gmsh(path);
  const fdem::GmshMesh left = fdem::read_gmsh(path, "left");
  const fdem::GmshMesh right = fdem::read_gmsh(path, "right");
  CHECK(left.num_tets() + right.num_tets() == all.num_tets());
  CHECK(left.num_tets() > 0);
  CHECK(right.num_tets() > 0);
  // Each half is 0.5 x 1 x 1 m.
  CHECK(std::abs(total_volume(left) - 0.5) <= 0.5e-12);
  CHECK(std::abs(total_volume(right) - 0.5) <= 0.5e-12);
  for (std::size_t i = 0; i < left.num_nodes(); ++i) CHECK(left.coords[3 * i] <= 0.5);
  for (std::size_t i = 0; i < right.num_nodes(); ++i) CHECK(right.coords[3 * i] >= 0.5);
  for (int tag : left.tet_physical) CHECK(tag == 1);
  for (int tag : right.tet_physical) CHECK(tag == 2);
  // Without a filter each tet carries the tag of its half.
  std::size_t tagged_left = 0;
  for (int tag : all.tet_physical) tagged_left += tag == 1 ? 1 : 0;
  CHECK(tagged_left == left.num_tets());

  const fdem::GmshMesh right_by_number = fdem::read_gmsh(path, "2");
  CHECK(right_by_number.tets == right.tets);
  CHECK(right_by_number.coords == right.coords);
}

TEST_CASE("coarse Brazilian disc: geometry of the Gmsh mesh", "[io][gmsh]") {
  const fdem::GmshMesh mesh = fdem::read_gmsh(data_file("brazilian_disc_coarse.msh"), "disc");
  CHECK(mesh.num_nodes() == 863);
  CHECK(mesh.num_tets() == 3552);
  CHECK(mesh.physical_names == std::map<std::string, int>{{"disc", 1}});
  const double radius = 0.025, thickness = 0.025;  // m; axis along z, centred at the origin
  for (std::size_t i = 0; i < mesh.num_nodes(); ++i) {
    const double x = mesh.coords[3 * i], y = mesh.coords[3 * i + 1], z = mesh.coords[3 * i + 2];
    CHECK(std::hypot(x, y) <= radius * (1 + 1e-12));
    CHECK(std::abs(z) <= thickness / 2 * (1 + 1e-12));
  }
  // Gmsh orders tet nodes with positive volume; the faceted cylinder lies inside the true one and
  // misses less than 1 % of its volume pi R^2 t at this size (3-5 mm facets on R = 25 mm).
  std::size_t inverted = 0;
  for (std::size_t t = 0; t < mesh.num_tets(); ++t) inverted += tet_volume(mesh, t) <= 0 ? 1 : 0;
  CHECK(inverted == 0);
  const double cylinder = kPi * radius * radius * thickness;
  CHECK(total_volume(mesh) < cylinder);
  CHECK(total_volume(mesh) > 0.99 * cylinder);
}

TEST_CASE("errors: missing file, directory, not a Gmsh file", "[io][gmsh][errors]") {
  const std::string missing = data_file("no_such_mesh.msh");
  std::string message = error_of(missing);
  CHECK(contains(message, missing));
  CHECK(contains(message, "does not exist"));

  message = error_of(std::string(FDEM_TEST_DATA) + "/gmsh");
  CHECK(contains(message, "is a directory"));

  message = error_of(data_file("not_a_mesh.stl"));
  CHECK(contains(message, "not_a_mesh.stl"));
  CHECK(contains(message, "line 1"));
  CHECK(contains(message, "not a Gmsh mesh file"));
  CHECK(contains(message, "expected '$MeshFormat'"));
  CHECK(contains(message, "found 'solid cube'"));
}

TEST_CASE("errors: MSH 2.2 and 4.0 files ask for a 4.1 re-export", "[io][gmsh][errors]") {
  std::string message = error_of(data_file("box_coarse_v22.msh"));
  CHECK(contains(message, "box_coarse_v22.msh"));
  CHECK(contains(message, "line 2"));
  CHECK(contains(message, "version 2.2 is not supported"));
  CHECK(contains(message, "re-export with Gmsh 4.1: gmsh -save -format msh41"));

  message = error_of(data_file("box_coarse_v40.msh"));
  CHECK(contains(message, "box_coarse_v40.msh"));
  CHECK(contains(message, "line 2"));
  CHECK(contains(message, "version 4 is not supported"));
  CHECK(contains(message, "gmsh -save -format msh41"));
}

TEST_CASE("errors: truncated files name the line or the byte offset", "[io][gmsh][errors]") {
  std::string message = error_of(data_file("cube_truncated_ascii.msh"));
  CHECK(contains(message, "cube_truncated_ascii.msh"));
  CHECK(contains(message, "line 151"));
  CHECK(contains(message, "(in $Nodes)"));
  CHECK(contains(message, "unexpected end of file while reading a node coordinate"));
  CHECK(contains(message, "truncated"));

  // The file is cut after 7600 bytes, just after the $Elements header that announces 278 elements.
  message = error_of(data_file("cube_truncated_binary.msh"));
  CHECK(contains(message, "cube_truncated_binary.msh"));
  CHECK(contains(message, "byte offset 7600"));
  CHECK(contains(message, "278 elements are announced"));
  CHECK(contains(message, "(in $Elements)"));
  CHECK(contains(message, "truncated"));
}

TEST_CASE("errors: binary file with the other byte order", "[io][gmsh][errors]") {
  const std::string message = error_of(data_file("binary_other_endian.msh"));
  CHECK(contains(message, "binary_other_endian.msh"));
  CHECK(contains(message, "byte offset 20"));  // right after "$MeshFormat\n4.1 1 8\n"
  CHECK(contains(message, "opposite byte order"));
  CHECK(contains(message, "expected 1"));
}

TEST_CASE("errors: tet referencing an unknown node tag", "[io][gmsh][errors]") {
  const std::string message = error_of(data_file("unknown_node.msh"));
  CHECK(contains(message, "unknown_node.msh"));
  CHECK(contains(message, "line 20"));
  CHECK(contains(message, "tetrahedron 2 references node tag 8"));
  CHECK(contains(message, "not defined in $Nodes"));
}

TEST_CASE("errors: surface mesh without tetrahedra", "[io][gmsh][errors]") {
  const std::string message = error_of(data_file("box_surface_only.msh"));
  CHECK(contains(message, "box_surface_only.msh"));
  CHECK(contains(message, "no 4-node tetrahedra"));
  CHECK(contains(message, "surface mesh"));
  CHECK(contains(message, "gmsh -3"));
}

TEST_CASE("errors: second-order tetrahedra", "[io][gmsh][errors]") {
  const std::string message = error_of(data_file("second_order_tet.msh"));
  CHECK(contains(message, "second_order_tet.msh"));
  CHECK(contains(message, "line 30"));
  CHECK(contains(message, "type 11"));
  CHECK(contains(message, "only linear 4-node tetrahedra"));
  CHECK(contains(message, "-order 1"));
}

TEST_CASE("errors: unknown and empty physical groups", "[io][gmsh][errors]") {
  std::string message = error_of(data_file("cube_two_volumes_binary.msh"), "middle");
  CHECK(contains(message, "cube_two_volumes_binary.msh"));
  CHECK(contains(message, "no 3D physical group named or numbered 'middle'"));
  CHECK(contains(message, "valid 3D physical groups (name and tag): 'left' 1, 'right' 2"));

  // "bottom" is a 2D group: not valid for selecting tetrahedra.
  message = error_of(data_file("cube_two_volumes_ascii.msh"), "bottom");
  CHECK(contains(message, "'bottom'"));
  CHECK(contains(message, "'left' 1, 'right' 2"));

  message = error_of(data_file("tet_no_groups.msh"), "rock");
  CHECK(contains(message, "the file defines no 3D physical groups"));

  message = error_of(data_file("empty_group.msh"), "void");
  CHECK(contains(message, "empty_group.msh"));
  CHECK(contains(message, "group 'void' (tag 4) exists but contains no 4-node tetrahedra"));
  CHECK(contains(message, "'rock' 3"));
}
