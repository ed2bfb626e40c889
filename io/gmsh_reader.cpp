// Gmsh MSH 4.1 reader: the whole file in memory, parsed by io/gmsh_parser, then the physical
// selection and the used nodes.
#include "io/gmsh_reader.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>
#include <system_error>

#include "core/error.hpp"
#include "io/gmsh_cursor.hpp"
#include "io/gmsh_parser.hpp"

namespace fdem {
namespace {

std::string read_whole_file(const std::string& path) {
  std::ifstream in = gmsh::open_mesh_file(path);
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  std::string data(size > 0 ? static_cast<std::size_t>(size) : 0, '\0');
  if (size < 0 || !in.read(data.data(), size)) {
    throw InputError("Gmsh mesh file '" + path + "' could not be read (I/O error).");
  }
  return data;
}

// Every node and tet of the file, as the parser hands them over.
struct WholeFile : GmshSink {
  GmshArrays all;

  void nodes_announced(std::int64_t count) override {
    all.node_tags.reserve(static_cast<std::size_t>(count));
    all.node_xyz.reserve(3 * static_cast<std::size_t>(count));
  }
  void node_tag(std::int64_t, std::int64_t tag) override { all.node_tags.push_back(tag); }
  void node_coords(std::int64_t, const double (&x)[3]) override {
    all.node_xyz.insert(all.node_xyz.end(), x, x + 3);
  }
  void tet(std::int64_t tag, int entity, const std::int64_t (&nodes)[4]) override {
    all.tet_nodes.insert(all.tet_nodes.end(), nodes, nodes + 4);
    all.tet_tags.push_back(tag);
    all.tet_entity.push_back(entity);
  }
};

// Every node's coordinates and the triangles of surface entities.
struct SurfaceTriangles : GmshSink {
  std::vector<double> xyz;
  std::vector<std::int64_t> corners;  // 3 per triangle, node indices
  std::vector<int> entity;

  void node_tag(std::int64_t, std::int64_t) override {}
  void node_coords(std::int64_t, const double (&x)[3]) override { xyz.insert(xyz.end(), x, x + 3); }
  void tet(std::int64_t, int, const std::int64_t (&)[4]) override {}
  void triangle(int e, const std::int64_t (&nodes)[3]) override {
    corners.insert(corners.end(), nodes, nodes + 3);
    entity.push_back(e);
  }
};

}  // namespace

std::vector<double> read_gmsh_surface(const std::string& path, const std::string& physical) {
  const std::string data = read_whole_file(path);
  gmsh::Cursor cur(path, data);
  SurfaceTriangles sink;
  const auto index = make_table_index();
  const GmshTables tables = parse_gmsh_sections(cur, path, *index, sink);
  const std::string file = "Gmsh file '" + path + "'";
  int group = 0;
  if (const auto it = tables.names_2d.find(physical); it != tables.names_2d.end()) {
    group = it->second;
  } else {
    bool known = false;
    try {
      std::size_t used = 0;
      group = std::stoi(physical, &used);
      known = used == physical.size();
      if (known) {
        known = false;
        for (const auto& [entity, tags] : tables.surface_physicals)
          known = known || std::find(tags.begin(), tags.end(), group) != tags.end();
      }
    } catch (const std::exception&) {
    }
    if (!known) {
      std::string names;
      for (const auto& [name, tag] : tables.names_2d)
        names += (names.empty() ? "" : ", ") + name + " (" + std::to_string(tag) + ")";
      throw InputError(file + " has no 2D physical group '" + physical + "'. Its 2D groups: " +
                       (names.empty() ? std::string("none (name the surface in Gmsh with "
                                                    "Physical Surface(\"top\") = {...};)")
                                      : names) +
                       ".");
    }
  }
  std::vector<double> out;
  for (std::size_t t = 0; t < sink.entity.size(); ++t) {
    const auto it = tables.surface_physicals.find(sink.entity[t]);
    if (it == tables.surface_physicals.end() ||
        std::find(it->second.begin(), it->second.end(), group) == it->second.end())
      continue;
    for (int k = 0; k < 3; ++k) {
      const std::size_t n = static_cast<std::size_t>(sink.corners[3 * t + k]);
      out.insert(out.end(), sink.xyz.begin() + 3 * n, sink.xyz.begin() + 3 * n + 3);
    }
  }
  if (out.empty())
    throw InputError(file + ": the 2D physical group '" + physical +
                     "' holds no 3-node triangles (save the surface mesh with the volume mesh: "
                     "Mesh.SaveAll = 1, or a Physical Surface for it)");
  return out;
}

GmshMesh read_gmsh(const std::string& path, const std::string& physical) {
  return parse_gmsh(read_whole_file(path), path, physical);
}

GmshMesh parse_gmsh(const std::string& data, const std::string& path, const std::string& physical) {
  gmsh::Cursor cur(path, data);
  WholeFile mesh;
  const auto index = make_table_index();
  const GmshTables tables = parse_gmsh_sections(cur, path, *index, mesh);
  return select_gmsh(tables, mesh.all, physical, "Gmsh file '" + path + "'");
}

GmshMesh select_gmsh(const GmshTables& tables, const GmshArrays& all, const std::string& physical,
                     const std::string& file) {
  const GmshSelection selection(tables, physical, file);
  if (all.tet_tags.empty()) throw InputError(no_tetrahedra_message(file));

  GmshMesh out;
  out.physical_names = tables.names_3d;
  std::vector<std::int64_t> new_index(all.node_tags.size(), -1);
  for (std::size_t t = 0; t < all.tet_tags.size(); ++t) {
    const int entity = all.tet_entity[t];
    if (!selection.kept(entity)) continue;
    out.tet_tags.push_back(all.tet_tags[t]);
    out.tet_physical.push_back(selection.physical_of(entity));
    for (int k = 0; k < 4; ++k) new_index[static_cast<std::size_t>(all.tet_nodes[4 * t + k])] = 0;
  }
  if (out.tet_tags.empty())
    throw InputError(selection.empty_message(static_cast<std::int64_t>(all.tet_tags.size())));

  // Keep used nodes in file order.
  std::int64_t next = 0;
  for (std::size_t i = 0; i < new_index.size(); ++i) {
    if (new_index[i] < 0) continue;
    new_index[i] = next++;
    out.node_tags.push_back(all.node_tags[i]);
    out.coords.insert(out.coords.end(), all.node_xyz.begin() + 3 * i,
                      all.node_xyz.begin() + 3 * i + 3);
  }
  if (next > std::numeric_limits<std::int32_t>::max()) {
    throw InputError(file + ": " + std::to_string(next) +
                     " nodes exceed the 2^31-1 nodes one mesh file may have in fdem; split the "
                     "model into several bodies.");
  }
  out.tets.reserve(4 * out.tet_tags.size());
  for (std::size_t t = 0; t < all.tet_tags.size(); ++t) {
    if (!selection.kept(all.tet_entity[t])) continue;
    for (int k = 0; k < 4; ++k) {
      out.tets.push_back(
          static_cast<std::int32_t>(new_index[static_cast<std::size_t>(all.tet_nodes[4 * t + k])]));
    }
  }
  return out;
}

}  // namespace fdem
