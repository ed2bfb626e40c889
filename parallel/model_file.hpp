// Model files: a Gmsh MSH 4.1 mesh prepared once (`fdem prepare`) into HDF5, so that N ranks can
// each read an equal slice of its tets and only the nodes their slice uses, and no process ever
// holds the whole mesh (docs/parallel.md, "Gmsh meshes at scale"; layout there).
//
// prepare_model_file streams the .msh once through io/gmsh_parser (the reader's checks and
// messages), with memory bounded by its window and block sizes, not by the mesh.  The file holds
// every node and every 4-node tetrahedron of the .msh in file order, the tets' volume entities and
// 3D physical tags, and the physical-group tables, so that a `physical:` selection made from it
// is the one read_gmsh makes from the .msh.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "io/gmsh_parser.hpp"
#include "io/gmsh_reader.hpp"

namespace fdem {

constexpr const char* model_file_format = "fdem-model";
constexpr std::int32_t model_file_version = 1;

struct PrepareOptions {
  std::int64_t block_rows = 1 << 16;                // rows written at a time (~100 B per row held)
  std::size_t window_bytes = std::size_t{4} << 20;  // bytes of the .msh held at a time
};

struct PrepareReport {
  std::int64_t nodes = 0, tets = 0;
};

// Reads the Gmsh file `msh` once and writes the model file `h5` (as `h5`.tmp, renamed when
// complete; the tets pass through a temporary `h5`.tets.tmp next to it).  Throws InputError for
// a bad mesh (the reader's messages; a file without 4-node tetrahedra is refused) and IoError
// when the model file cannot be written.
PrepareReport prepare_model_file(const std::string& msh, const std::string& h5,
                                 const PrepareOptions& options = {});

// The root attributes of a model file.
struct ModelFileHeader {
  std::int32_t version = 0;
  std::int64_t n_nodes = 0, n_tets = 0;
  std::string source;  // the .msh it was prepared from, as named to prepare
  std::int64_t source_bytes = 0, source_mtime_ns = 0;
};

// True when `path` is an HDF5 file (a model file or another one); false for anything else (a
// Gmsh file).  Never throws.
bool is_hdf5_file(const std::string& path);

// The header of the model file `path`, checked (seal, format, version, header checksum).
// Throws InputError.
ModelFileHeader read_model_file_header(const std::string& path);

// One process: the whole mesh of a model file with a `physical:` selection — the GmshMesh
// read_gmsh gives for the .msh it was prepared from.  Throws InputError (damaged or foreign file,
// a tet referencing a node beyond the table, a non-finite coordinate, the selection's errors).
GmshMesh read_model_file(const std::string& path, const std::string& physical = "");

// One process: everything the file holds (tests).
struct ModelFileContent {
  ModelFileHeader header;
  GmshTables tables;
  std::vector<std::int64_t> node_tag;      // n
  std::vector<double> node_x;              // n × 3
  std::vector<std::int64_t> tet_nodes;     // m × 4, rows of the node table
  std::vector<std::int64_t> tet_tag;       // m, Gmsh element tags
  std::vector<std::int32_t> tet_entity;    // m, volume entity tag (-1: not in a volume block)
  std::vector<std::int32_t> tet_physical;  // m, the entity's first 3D physical tag (0: none)
};
ModelFileContent read_model_file_content(const std::string& path);

// Writes `content` as the model file `h5` (checksums, seal): tests and tools that need a model
// file with given content (header: source, source_bytes, source_mtime_ns are kept; tet_physical
// is derived from the tables as prepare derives it).  Throws IoError.
void write_model_file(const ModelFileContent& content, const std::string& h5);

}  // namespace fdem
