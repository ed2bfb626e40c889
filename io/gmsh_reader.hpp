// Reader for Gmsh MSH 4.1 meshes (ASCII and binary): the 4-node tetrahedra of a file, optionally
// restricted to one 3D physical group.  Errors are fdem::InputError naming the file, the line
// (ASCII) or byte offset (binary), and what was expected.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace fdem {

struct GmshMesh {
  std::vector<double> coords;           // 3*n node coordinates (m), only nodes used by the tets
  std::vector<std::int64_t> node_tags;  // Gmsh node tag of each node (file order)
  std::vector<std::int32_t> tets;       // 4*m, 0-based indices into coords (node order as in file)
  std::vector<std::int64_t> tet_tags;   // Gmsh element tag of each tet (for error messages)
  std::vector<int> tet_physical;  // 3D physical tag of each tet (0 if its volume entity has none)
  std::map<std::string, int> physical_names;  // 3D physical groups: name -> tag

  std::size_t num_nodes() const { return node_tags.size(); }
  std::size_t num_tets() const { return tet_tags.size(); }
};

// Reads all 4-node tetrahedra (Gmsh element type 4) of an MSH 4.1 file.  Nodes not used by a kept
// tet are dropped; the remaining ones keep their file order.  Lines, triangles and points are
// skipped; other volume elements (10-node tets, hexahedra, prisms, pyramids) are errors, since
// silently dropping them would lose part of the body.  Unknown sections ($Periodic, $NodeData,
// $Comments, ...) are skipped.
//
// If `physical` is non-empty, keeps only tets whose volume entity belongs to the 3D physical group
// of that name (or of that number, given as a string); tet_physical is then that group's tag.
// Without a filter, a tet whose volume entity is in several groups gets the first one listed.
//
// Throws fdem::InputError: file missing or unreadable, not a Gmsh file, MSH version other than 4.1,
// truncated or malformed file, a tet referencing an unknown node tag, no tetrahedra at all, unknown
// physical group, physical group without tetrahedra.
GmshMesh read_gmsh(const std::string& path, const std::string& physical = "");

// The same from the file's bytes (`path` names it in messages): the fuzzing entry point.
GmshMesh parse_gmsh(const std::string& data, const std::string& path,
                    const std::string& physical = "");

// The triangles of a 2D physical group (name or number) of an MSH 4.1 file: 9 coordinates (m)
// per triangle, corners as in the file.  Throws InputError naming the file and the group for an
// unknown group (listing the file's 2D groups) or a group without 3-node triangles, and as
// read_gmsh does for a malformed file.
std::vector<double> read_gmsh_surface(const std::string& path, const std::string& physical);

struct GmshTables;

// Every node and 4-node tet of a file, in file order, as io/gmsh_parser reads them (or as a
// prepared model file holds them).
struct GmshArrays {
  std::vector<std::int64_t> node_tags;
  std::vector<double> node_xyz;         // 3 per node
  std::vector<std::int64_t> tet_nodes;  // 4 per tet, indices into the nodes
  std::vector<std::int64_t> tet_tags;
  std::vector<std::int32_t> tet_entity;  // volume entity tag (-1: not in a volume block)
};

// What read_gmsh keeps of a parsed file: the selected tets, the nodes they use (file order).
// `file` starts the messages ("Gmsh file 'x.msh'").  Throws InputError as read_gmsh does.
GmshMesh select_gmsh(const GmshTables& tables, const GmshArrays& all, const std::string& physical,
                     const std::string& file);

}  // namespace fdem
