// Gmsh MSH 4.1 sections.  Layout reference: Gmsh reference manual, section "MSH file format".
#include "io/gmsh_parser.hpp"

#include <algorithm>
#include <charconv>
#include <iterator>
#include <set>
#include <system_error>
#include <unordered_map>

#include "core/error.hpp"
#include "io/gmsh_cursor.hpp"

namespace fdem {

using gmsh::Cursor;
using gmsh::excerpt;

namespace {

constexpr int kLinearTet = 4;
constexpr int kTriangle = 2;

struct ElementType {
  int num_nodes;
  int dim;
  const char* name;
};

// Gmsh element types up to order 3 (numbers fixed by the MSH format); enough to skip any of them.
const ElementType* find_element_type(int type) {
  static const std::map<int, ElementType> types = {
      {1, {2, 1, "2-node line"}},
      {2, {3, 2, "3-node triangle"}},
      {3, {4, 2, "4-node quadrangle"}},
      {4, {4, 3, "4-node tetrahedron"}},
      {5, {8, 3, "8-node hexahedron"}},
      {6, {6, 3, "6-node prism"}},
      {7, {5, 3, "5-node pyramid"}},
      {8, {3, 1, "3-node line"}},
      {9, {6, 2, "6-node triangle"}},
      {10, {9, 2, "9-node quadrangle"}},
      {11, {10, 3, "10-node (second-order) tetrahedron"}},
      {12, {27, 3, "27-node hexahedron"}},
      {13, {18, 3, "18-node prism"}},
      {14, {14, 3, "14-node pyramid"}},
      {15, {1, 0, "1-node point"}},
      {16, {8, 2, "8-node quadrangle"}},
      {17, {20, 3, "20-node hexahedron"}},
      {18, {15, 3, "15-node prism"}},
      {19, {13, 3, "13-node pyramid"}},
      {20, {9, 2, "9-node triangle"}},
      {21, {10, 2, "10-node triangle"}},
      {22, {12, 2, "12-node triangle"}},
      {23, {15, 2, "15-node triangle"}},
      {24, {15, 2, "15-node triangle"}},
      {25, {21, 2, "21-node triangle"}},
      {26, {4, 1, "4-node line"}},
      {27, {5, 1, "5-node line"}},
      {28, {6, 1, "6-node line"}},
      {29, {20, 3, "20-node (third-order) tetrahedron"}},
      {30, {35, 3, "35-node (fourth-order) tetrahedron"}},
      {31, {56, 3, "56-node (fifth-order) tetrahedron"}},
  };
  const auto it = types.find(type);
  return it == types.end() ? nullptr : &it->second;
}

class TableIndex : public NodeTagIndex {
 public:
  void reserve(std::int64_t min_tag, std::int64_t max_tag, std::int64_t count) override {
    min_tag_ = min_tag;
    // Tags are non-negative and count is bounded by the file size, so neither side overflows.
    dense_ = count > 0 && max_tag >= min_tag && max_tag - min_tag < 4 * count + 1024;
    if (dense_) {
      table_.assign(static_cast<std::size_t>(max_tag - min_tag + 1), -1);
    } else {
      map_.reserve(static_cast<std::size_t>(count));
    }
  }
  bool insert(std::int64_t tag, std::int64_t index) override {
    if (dense_ && tag >= min_tag_ && tag - min_tag_ < static_cast<std::int64_t>(table_.size())) {
      std::int64_t& slot = table_[static_cast<std::size_t>(tag - min_tag_)];
      if (slot >= 0) return false;
      slot = index;
      return true;
    }
    return map_.emplace(tag, index).second;  // also takes tags outside the announced range
  }
  std::int64_t find(std::int64_t tag) override {
    if (dense_ && tag >= min_tag_ && tag - min_tag_ < static_cast<std::int64_t>(table_.size())) {
      const std::int64_t slot = table_[static_cast<std::size_t>(tag - min_tag_)];
      if (slot >= 0) return slot;
    }
    const auto it = map_.find(tag);
    return it == map_.end() ? -1 : it->second;
  }

 private:
  bool dense_ = false;
  std::int64_t min_tag_ = 0;
  std::vector<std::int64_t> table_;
  std::unordered_map<std::int64_t, std::int64_t> map_;
};

// Disjoint runs [first, first + count) of tags at indices [index, index + count). Tags are
// non-negative, so run ends are compared as differences: first + count may exceed int64.
class RunIndex : public NodeTagIndex {
 public:
  void reserve(std::int64_t, std::int64_t, std::int64_t) override {}
  bool insert(std::int64_t tag, std::int64_t index) override {
    if (last_ != runs_.end()) {  // the common case: the next tag of the last run
      Run& run = last_->second;
      const auto next = std::next(last_);
      if (tag > last_->first && tag - last_->first == run.count && index == run.index + run.count &&
          (next == runs_.end() || next->first > tag)) {
        ++run.count;
        return true;
      }
    }
    auto after = runs_.upper_bound(tag);
    if (after != runs_.begin()) {
      const auto before = std::prev(after);
      if (tag - before->first < before->second.count) return false;  // before->first <= tag
    }
    last_ = runs_.emplace_hint(after, tag, Run{1, index});
    return true;
  }
  std::int64_t find(std::int64_t tag) override {
    if (found_ == runs_.end() || tag < found_->first ||
        tag - found_->first >= found_->second.count) {
      auto after = runs_.upper_bound(tag);
      if (after == runs_.begin()) return -1;
      found_ = std::prev(after);
      if (tag - found_->first >= found_->second.count) {
        found_ = runs_.end();
        return -1;
      }
    }
    return found_->second.index + (tag - found_->first);
  }

 private:
  struct Run {
    std::int64_t count, index;
  };
  std::map<std::int64_t, Run> runs_;
  std::map<std::int64_t, Run>::iterator last_ = runs_.end(), found_ = runs_.end();
};

void read_mesh_format(Cursor& cur, const std::string& path) {
  cur.skip_space();
  if (cur.at_end()) {
    cur.fail_at(0, "the file is empty; expected a Gmsh mesh starting with '$MeshFormat'.");
  }
  const std::uint64_t first_start = cur.pos();
  const std::string first = cur.line();
  if (first != "$MeshFormat") {
    cur.fail_at(first_start,
                "not a Gmsh mesh file: expected '$MeshFormat' as the first line, found '" +
                    excerpt(first) + "'. fdem reads meshes written by Gmsh in MSH 4.1 format.");
  }
  cur.section = "$MeshFormat";
  const std::string version(cur.ascii_token("the format version"));
  const std::uint64_t version_start = cur.value_start();
  if (version != "4.1") {
    cur.fail_at(version_start,
                "MSH format version " + version +
                    " is not supported; fdem reads MSH 4.1 only (ASCII or binary): re-export with "
                    "Gmsh 4.1: gmsh -save -format msh41 " +
                    path + " -o new_mesh.msh");
  }
  const std::int64_t file_type = cur.ascii_int("the file type (0 = ASCII, 1 = binary)");
  if (file_type != 0 && file_type != 1) {
    cur.fail_at(cur.value_start(), "expected the file type 0 (ASCII) or 1 (binary), found " +
                                       std::to_string(file_type) + ".");
  }
  const std::int64_t data_size = cur.ascii_int("the data size");
  if (data_size != 8) {
    cur.fail_at(cur.value_start(), "expected data size 8 (64-bit size_t), found " +
                                       std::to_string(data_size) +
                                       "; re-export the mesh with a 64-bit Gmsh.");
  }
  if (file_type == 1) {
    cur.skip_rest_of_line();
    cur.binary = true;
    const std::int32_t one = cur.raw<std::int32_t>("the binary endianness check (the int 1)");
    if (one != 1) {
      constexpr std::int32_t kSwappedOne = 0x01000000;
      cur.fail_at(cur.value_start(),
                  one == kSwappedOne
                      ? std::string("the binary file was written on a machine with the opposite "
                                    "byte order (endianness check reads 16777216, expected 1); "
                                    "re-export it as ASCII: gmsh -save -format msh41 ") +
                            path + " -o new_mesh.msh"
                      : "expected the endianness check value 1, found " + std::to_string(one) +
                            "; the binary header is damaged.");
    }
  }
  cur.expect_end("MeshFormat");
}

void read_physical_names(Cursor& cur, GmshTables& mesh) {
  // Always ASCII, even in binary files.
  const std::int64_t count = cur.ascii_int("the number of physical names");
  for (std::int64_t i = 0; i < count; ++i) {
    const std::int64_t dim = cur.ascii_int("a physical group dimension (0-3)");
    const std::int64_t tag = cur.ascii_int("a physical group tag");
    const std::string name = cur.ascii_quoted("a physical group name");
    if (dim == 3) {
      mesh.names_3d.emplace(name, static_cast<int>(tag));
      mesh.tag_names_3d.emplace(static_cast<int>(tag), name);
    } else if (dim == 2) {
      mesh.names_2d.emplace(name, static_cast<int>(tag));
    }
  }
  cur.expect_end("PhysicalNames");
}

void read_entities(Cursor& cur, GmshTables& mesh) {
  std::int64_t counts[4];
  const char* kinds[4] = {"point", "curve", "surface", "volume"};
  for (int dim = 0; dim < 4; ++dim) {
    counts[dim] = cur.read_size(std::string("the number of ") + kinds[dim] + " entities");
  }
  for (int dim = 0; dim < 4; ++dim) {
    const std::string kind = kinds[dim];
    cur.check_count(counts[dim], 4 + 3 * 8 + 8, kind + " entities");
    for (std::int64_t e = 0; e < counts[dim]; ++e) {
      const int tag = cur.read_int(kind + " entity tag");
      const int num_coords = dim == 0 ? 3 : 6;  // a point, or a bounding box
      for (int k = 0; k < num_coords; ++k) cur.read_double(kind + " entity coordinates");
      const std::int64_t num_physicals = cur.read_size("the number of physical tags");
      cur.check_count(num_physicals, 4, "physical tags");
      std::vector<int> physicals;
      for (std::int64_t p = 0; p < num_physicals; ++p) {
        physicals.push_back(cur.read_int("a physical tag"));
      }
      if (dim > 0) {
        const std::int64_t num_bounding = cur.read_size("the number of bounding entities");
        cur.check_count(num_bounding, 4, "bounding entities");
        for (std::int64_t b = 0; b < num_bounding; ++b) cur.read_int("a bounding entity tag");
      }
      if (dim == 3) mesh.volume_physicals[tag] = std::move(physicals);
      if (dim == 2) mesh.surface_physicals[tag] = std::move(physicals);
    }
  }
  cur.expect_end("Entities");
}

void read_nodes(Cursor& cur, GmshTables& mesh, NodeTagIndex& index, GmshSink& sink) {
  const std::int64_t num_blocks = cur.read_size("the number of node blocks");
  const std::int64_t num_nodes = cur.read_size("the number of nodes");
  const std::int64_t min_tag = cur.read_size("the smallest node tag");
  const std::int64_t max_tag = cur.read_size("the largest node tag");
  cur.check_count(num_blocks, 3 * 4 + 8, "node blocks");
  cur.check_count(num_nodes, 8 + 3 * 8, "nodes");
  index.reserve(min_tag, max_tag, num_nodes);
  sink.nodes_announced(num_nodes);

  std::int64_t read = 0;
  for (std::int64_t b = 0; b < num_blocks; ++b) {
    const int entity_dim = cur.read_int("the entity dimension of a node block");
    if (entity_dim < 0 || entity_dim > 3) {
      cur.fail_at(cur.value_start(),
                  "expected an entity dimension 0-3, found " + std::to_string(entity_dim) + ".");
    }
    cur.read_int("the entity tag of a node block");
    const int parametric = cur.read_int("the parametric flag (0 or 1)");
    if (parametric != 0 && parametric != 1) {
      cur.fail_at(cur.value_start(),
                  "expected the parametric flag 0 or 1, found " + std::to_string(parametric) + ".");
    }
    const std::int64_t count = cur.read_size("the number of nodes in the block");
    const int values_per_node = 3 + (parametric ? entity_dim : 0);  // x y z [u [v [w]]]
    cur.check_count(count, 8 + 8 * values_per_node, "nodes of a node block");

    // A tag defined twice is reported after the block's coordinates (as a reader that checks the
    // block's tags once it holds the block would), at the first repeated tag.
    std::int64_t repeated = -1;
    std::uint64_t repeated_at = 0;
    for (std::int64_t i = 0; i < count; ++i) {
      const std::int64_t tag = cur.read_size("a node tag");
      if (!index.insert(tag, read + i) && repeated < 0) {
        repeated = tag;
        repeated_at = cur.value_start();
      }
      sink.node_tag(read + i, tag);
    }
    for (std::int64_t i = 0; i < count; ++i) {
      double x[3];
      for (double& value : x) value = cur.read_double("a node coordinate");
      for (int k = 3; k < values_per_node; ++k) cur.read_double("a parametric node coordinate");
      sink.node_coords(read + i, x);
    }
    if (repeated >= 0)
      cur.fail_at(repeated_at, "node tag " + std::to_string(repeated) +
                                   " is defined twice; node tags must be unique.");
    read += count;
  }
  if (read != num_nodes) {
    cur.fail_at(cur.pos(), "the section header announces " + std::to_string(num_nodes) +
                               " nodes but its blocks hold " + std::to_string(read) +
                               "; the file is damaged.");
  }
  cur.expect_end("Nodes");
  mesh.n_nodes = read;
}

void read_elements(Cursor& cur, GmshTables& mesh, NodeTagIndex& index, GmshSink& sink) {
  const std::int64_t num_blocks = cur.read_size("the number of element blocks");
  const std::int64_t num_elements = cur.read_size("the number of elements");
  cur.read_size("the smallest element tag");
  cur.read_size("the largest element tag");
  cur.check_count(num_blocks, 3 * 4 + 8, "element blocks");
  cur.check_count(num_elements, 2 * 8, "elements");

  std::int64_t total = 0;
  for (std::int64_t b = 0; b < num_blocks; ++b) {
    const int entity_dim = cur.read_int("the entity dimension of an element block");
    const std::uint64_t block_start = cur.value_start();
    const int entity_tag = cur.read_int("the entity tag of an element block");
    const int type = cur.read_int("the element type");
    const std::uint64_t type_start = cur.value_start();
    const std::int64_t count = cur.read_size("the number of elements in the block");
    total += count;
    const ElementType* info = find_element_type(type);
    if (info == nullptr) {
      cur.fail_at(type_start, "element type " + std::to_string(type) +
                                  " is not supported; fdem reads 4-node tetrahedra (type 4) and "
                                  "skips points, lines, triangles and quadrangles.");
    }
    cur.check_count(count, 8 * (1 + static_cast<std::size_t>(info->num_nodes)), "elements");

    if (type == kLinearTet) {
      for (std::int64_t i = 0; i < count; ++i) {
        const std::int64_t tag = cur.read_size("an element tag");
        std::int64_t nodes[4];
        for (int k = 0; k < 4; ++k) {
          const std::int64_t node_tag =
              cur.read_size("a node tag of tetrahedron " + std::to_string(tag));
          nodes[k] = index.find(node_tag);
          if (nodes[k] < 0) {
            cur.fail_at(cur.value_start(), "tetrahedron " + std::to_string(tag) +
                                               " references node tag " + std::to_string(node_tag) +
                                               ", which is not defined in $Nodes.");
          }
        }
        sink.tet(tag, entity_dim == 3 ? entity_tag : -1, nodes);
        ++mesh.n_tets;
      }
      continue;
    }
    if (type == kTriangle && entity_dim == 2) {
      for (std::int64_t i = 0; i < count; ++i) {
        const std::int64_t tag = cur.read_size("an element tag");
        std::int64_t nodes[3];
        for (int k = 0; k < 3; ++k) {
          const std::int64_t node_tag =
              cur.read_size("a node tag of triangle " + std::to_string(tag));
          nodes[k] = index.find(node_tag);
          if (nodes[k] < 0)
            cur.fail_at(cur.value_start(), "triangle " + std::to_string(tag) +
                                               " references node tag " + std::to_string(node_tag) +
                                               ", which is not defined in $Nodes.");
        }
        sink.triangle(entity_tag, nodes);
      }
      continue;
    }
    if (info->dim == 3 && count > 0) {
      const bool higher_order_tet = type == 11 || (type >= 29 && type <= 31);
      mesh.unsupported.push_back(
          {entity_tag, cur.location(block_start) + " (in $Elements): found " +
                           std::to_string(count) + " element(s) of type " + std::to_string(type) +
                           " (" + info->name + ") in volume entity " + std::to_string(entity_tag) +
                           "; fdem supports only linear 4-node tetrahedra (type 4). " +
                           (higher_order_tet ? "Mesh with first-order elements (gmsh -3 -order 1, "
                                               "or Mesh.ElementOrder = 1 in the .geo file)."
                                             : "Mesh this volume with tetrahedra only (no "
                                               "Recombine).")});
    }
    // Skip: element tag and node tags of each element.
    const std::uint64_t values = static_cast<std::uint64_t>(count) * (1 + info->num_nodes);
    if (cur.binary) {
      cur.skip_bytes(values * 8, std::string("elements of type ") + info->name);
    } else {
      for (std::uint64_t v = 0; v < values; ++v) {
        cur.read_size(std::string("a tag of a ") + info->name);
      }
    }
  }
  if (total != num_elements) {
    cur.fail_at(cur.pos(), "the section header announces " + std::to_string(num_elements) +
                               " elements but its blocks hold " + std::to_string(total) +
                               "; the file is damaged.");
  }
  cur.expect_end("Elements");
}

std::string list_groups(const GmshTables& mesh) {
  std::set<int> tags;
  for (const auto& entry : mesh.tag_names_3d) tags.insert(entry.first);
  for (const auto& entry : mesh.volume_physicals)
    tags.insert(entry.second.begin(), entry.second.end());
  if (tags.empty()) {
    return "the file defines no 3D physical groups (add 'Physical Volume(\"name\") = {...};' to "
           "the .geo file and mesh it again)";
  }
  std::string out = "valid 3D physical groups (name and tag): ";
  bool first = true;
  for (const int tag : tags) {
    const auto it = mesh.tag_names_3d.find(tag);
    out += (first ? "" : ", ") +
           (it == mesh.tag_names_3d.end() ? std::string("(unnamed)") : "'" + it->second + "'") +
           " " + std::to_string(tag);
    first = false;
  }
  return out;
}

}  // namespace

std::unique_ptr<NodeTagIndex> make_table_index() {
  return std::make_unique<TableIndex>();
}

std::unique_ptr<NodeTagIndex> make_run_index() {
  return std::make_unique<RunIndex>();
}

GmshTables parse_gmsh_sections(Cursor& cur, const std::string& path, NodeTagIndex& index,
                               GmshSink& sink) {
  GmshTables mesh;
  bool have_nodes = false, have_elements = false;
  read_mesh_format(cur, path);
  while (true) {
    cur.section.clear();
    cur.skip_space();
    if (cur.at_end()) break;
    const std::uint64_t start = cur.pos();
    const std::string header = cur.line();
    if (header.empty() || header[0] != '$') continue;  // text between sections is ignored
    const std::string name(header.substr(1));
    cur.section = "$" + name;
    if (name.rfind("End", 0) == 0) {
      cur.fail_at(start, "found '" + excerpt(header) + "' without a matching section start.");
    } else if (name == "MeshFormat") {
      cur.fail_at(start, "a second '$MeshFormat' section; the file is damaged.");
    } else if (name == "PhysicalNames") {
      read_physical_names(cur, mesh);
    } else if (name == "Entities") {
      read_entities(cur, mesh);
    } else if (name == "Nodes") {
      if (have_nodes) cur.fail_at(start, "a second '$Nodes' section; the file is damaged.");
      read_nodes(cur, mesh, index, sink);
      have_nodes = true;
    } else if (name == "Elements") {
      if (!have_nodes) {
        cur.fail_at(start, "'$Elements' comes before '$Nodes'; expected $Nodes first.");
      }
      if (have_elements) {
        cur.fail_at(start, "a second '$Elements' section; the file is damaged.");
      }
      read_elements(cur, mesh, index, sink);
      have_elements = true;
    } else {
      cur.skip_section(name, start);  // $Periodic, $NodeData, $Comments, $PartitionedEntities...
    }
  }
  cur.section.clear();
  return mesh;
}

std::string no_tetrahedra_message(const std::string& file) {
  return file +
         " contains no 4-node tetrahedra (element type 4); expected a 3D mesh. The "
         "file may be a surface mesh: mesh it in 3D with `gmsh -3 your_model.geo`.";
}

GmshSelection::GmshSelection(const GmshTables& tables, const std::string& physical,
                             const std::string& file)
    : tables_(tables), file_(file) {
  // A 3D group name, else a 3D group number.
  if (!physical.empty()) {
    const auto by_name = tables.names_3d.find(physical);
    if (by_name != tables.names_3d.end()) {
      filter_ = by_name->second;
    } else {
      int number = 0;
      const auto [end, ec] =
          std::from_chars(physical.data(), physical.data() + physical.size(), number);
      const bool is_number = ec == std::errc() && end == physical.data() + physical.size();
      bool known = is_number && tables.tag_names_3d.count(number) > 0;
      for (const auto& entry : tables.volume_physicals) {
        const std::vector<int>& tags = entry.second;
        known = known || (is_number && std::find(tags.begin(), tags.end(), number) != tags.end());
      }
      if (!known) {
        throw InputError(file + ": no 3D physical group named or numbered '" + physical + "'; " +
                         list_groups(tables) + ".");
      }
      filter_ = number;
    }
    label_ = "'" + physical + "' (tag " + std::to_string(filter_) + ")";
  }
  for (const GmshTables::Unsupported& block : tables.unsupported) {
    if (kept(block.entity_tag)) throw InputError(file + ", " + block.message);
  }
}

bool GmshSelection::kept(int entity) const {
  if (filter_ == 0) return true;
  const auto it = tables_.volume_physicals.find(entity);
  return it != tables_.volume_physicals.end() &&
         std::find(it->second.begin(), it->second.end(), filter_) != it->second.end();
}

int GmshSelection::physical_of(int entity) const {
  if (filter_ != 0) return filter_;
  const auto it = tables_.volume_physicals.find(entity);
  return it != tables_.volume_physicals.end() && !it->second.empty() ? it->second[0] : 0;
}

std::string GmshSelection::empty_message(std::int64_t total_tets) const {
  return file_ + ": the 3D physical group " + label_ +
         " exists but contains no 4-node tetrahedra (its volumes were not meshed, or "
         "the group lists no volume); the file's " +
         std::to_string(total_tets) + " tetrahedra lie in other groups; " + list_groups(tables_) +
         ".";
}

}  // namespace fdem
