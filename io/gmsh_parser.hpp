// The Gmsh MSH 4.1 parser shared by read_gmsh (the whole file in memory, io/gmsh_reader) and
// `fdem prepare` (the file streamed once into an HDF5 model file, parallel/model_file): it walks
// the sections, checks everything the reader checks (with the file, line or byte offset, and what
// is wrong), keeps the small tables (physical groups, volume entities, unusable volume blocks) and
// hands nodes and tetrahedra to a sink as it meets them.  Selecting a physical group is a separate
// step (GmshSelection), so that a prepared file can be selected from later exactly as read_gmsh
// selects from the .msh.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace fdem {

namespace gmsh {
class Cursor;
}

// What the parser keeps besides nodes and tets (small: one entry per group, entity or block).
struct GmshTables {
  std::map<std::string, int> names_3d;  // $PhysicalNames, dimension 3: name -> tag
  std::map<int, std::string> tag_names_3d;
  std::map<int, std::vector<int>> volume_physicals;   // volume entity tag -> physical tags
  std::map<std::string, int> names_2d;                // $PhysicalNames, dimension 2
  std::map<int, std::vector<int>> surface_physicals;  // surface entity tag -> physical tags
  // Blocks of volume elements fdem cannot use (10-node tets, hexahedra, ...): an error when a
  // selected volume holds one.  message: location and advice, after "Gmsh file '...', ".
  struct Unsupported {
    int entity_tag;
    std::string message;
  };
  std::vector<Unsupported> unsupported;
  std::int64_t n_nodes = 0, n_tets = 0;  // all nodes of $Nodes, all 4-node tets of $Elements
};

// Receives what the parser reads, in file order.  Node index = position in $Nodes (0-based).
class GmshSink {
 public:
  virtual ~GmshSink() = default;
  virtual void nodes_announced(std::int64_t count) { (void)count; }
  virtual void node_tag(std::int64_t index, std::int64_t tag) = 0;
  virtual void node_coords(std::int64_t index, const double (&x)[3]) = 0;
  // A 4-node tetrahedron: element tag, volume entity tag (-1 if its block is not a volume), node
  // indices of its corners.
  virtual void tet(std::int64_t tag, int entity, const std::int64_t (&nodes)[4]) = 0;
  // A 3-node triangle of a surface entity (surface loads on a physical surface); ignored unless
  // a sink wants them.
  virtual void triangle(int entity, const std::int64_t (&nodes)[3]) {
    (void)entity;
    (void)nodes;
  }
};

// Node tag -> node index.
class NodeTagIndex {
 public:
  virtual ~NodeTagIndex() = default;
  virtual void reserve(std::int64_t min_tag, std::int64_t max_tag, std::int64_t count) = 0;
  virtual bool insert(std::int64_t tag, std::int64_t index) = 0;  // false: tag already present
  virtual std::int64_t find(std::int64_t tag) = 0;                // -1: unknown
};

// A dense table when the tags are compact, a hash otherwise (memory ∝ nodes).
std::unique_ptr<NodeTagIndex> make_table_index();
// Runs of consecutive tags at consecutive indices (memory ∝ runs: Gmsh numbers the nodes of
// each node block consecutively, so a file it wrote has about one run per block).
std::unique_ptr<NodeTagIndex> make_run_index();

// Parses the whole file through `cur`, handing nodes and tets to `sink`.  Throws InputError for a
// malformed file (what read_gmsh's documentation lists); a file without 4-node tetrahedra is left
// to the caller (read_gmsh names an unknown physical group first).
GmshTables parse_gmsh_sections(gmsh::Cursor& cur, const std::string& path, NodeTagIndex& index,
                               GmshSink& sink);

// "contains no 4-node tetrahedra" message for a file labelled `file` ("Gmsh file 'x.msh'").
std::string no_tetrahedra_message(const std::string& file);

// The tets a `physical:` selection keeps.  The constructor throws InputError for an unknown group
// and for unusable volume elements in a kept volume, with `file` ("Gmsh file 'x.msh'") first.
class GmshSelection {
 public:
  GmshSelection(const GmshTables& tables, const std::string& physical, const std::string& file);
  bool kept(int entity) const;
  // 3D physical tag of a kept tet: the selected group, else the entity's first group, else 0.
  int physical_of(int entity) const;
  // The message when the group keeps no tet of the file's `total_tets`.
  std::string empty_message(std::int64_t total_tets) const;

 private:
  const GmshTables& tables_;
  std::string file_, label_;
  int filter_ = 0;
};

}  // namespace fdem
