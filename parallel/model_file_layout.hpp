// Layout of a model file (parallel/model_file.hpp; docs/parallel.md, "Gmsh meshes at scale"),
// shared by its writer and its readers.  Internal to parallel/.
#pragma once

#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "io/gmsh_parser.hpp"
#include "parallel/checkpoint_checksum.hpp"
#include "parallel/model_file.hpp"

namespace fdem::model_file {

// The big datasets: name, values per row (0: one-dimensional).
struct DatasetInfo {
  const char* name;
  int width;
};
constexpr DatasetInfo node_tag{"/nodes/tag", 0};
constexpr DatasetInfo node_x{"/nodes/x", 3};
constexpr DatasetInfo tet_nodes{"/tets/nodes", 4};
constexpr DatasetInfo tet_tag{"/tets/tag", 0};
constexpr DatasetInfo tet_entity{"/tets/entity", 0};
constexpr DatasetInfo tet_physical{"/tets/physical", 0};
// The tables (small, read whole by every reader): (volume entity, physical tag) pairs; the 3D
// physical names as text lines "N <tag> <name>" (name -> tag) and "T <tag> <name>" (tag ->
// name; the two differ only when a file repeats a name or a tag); the unusable volume blocks'
// entities and their messages (one line each).
constexpr DatasetInfo physical_volumes{"/physical/volumes", 2};
constexpr DatasetInfo physical_names{"/physical/names", 0};
constexpr DatasetInfo unsupported_entity{"/unsupported/entity", 0};
constexpr DatasetInfo unsupported_messages{"/unsupported/messages", 0};

// Messages about a damaged model file (the same from every reader).  `label`: Reader::label().
inline std::string node_row_message(const std::string& label, std::int64_t tag,
                                    std::int64_t tet_row, std::int64_t node_row,
                                    std::int64_t n_nodes) {
  return label + ": tetrahedron " + std::to_string(tag) + " (row " + std::to_string(tet_row) +
         " of /tets/nodes) references node row " + std::to_string(node_row) +
         ", but the node table has " + std::to_string(n_nodes) +
         " rows; the file is damaged: prepare it again";
}
inline std::string non_finite_node_message(const std::string& label, std::int64_t tag) {
  return label + ": node " + std::to_string(tag) +
         " has a coordinate that is NaN or infinite; the file is damaged: prepare it again";
}

// The header's checksum: its values as text.
inline std::uint64_t header_checksum(const ModelFileHeader& h) {
  std::ostringstream out;
  out << h.version << ' ' << h.n_nodes << ' ' << h.n_tets << ' ' << h.source.size() << ':'
      << h.source << ' ' << h.source_bytes << ' ' << h.source_mtime_ns;
  return text_checksum(out.str());
}

// The tables as the datasets hold them.
struct TableRows {
  std::vector<std::int32_t> volumes;  // pairs
  std::vector<std::uint8_t> names;
  std::vector<std::int32_t> unsupported_entity;
  std::vector<std::uint8_t> unsupported_messages;
};

inline std::vector<std::uint8_t> bytes_of(const std::string& text) {
  return std::vector<std::uint8_t>(text.begin(), text.end());
}

inline TableRows table_rows(const GmshTables& tables) {
  TableRows rows;
  for (const auto& [entity, physicals] : tables.volume_physicals)
    for (int p : physicals) rows.volumes.insert(rows.volumes.end(), {entity, p});
  std::string names, messages;
  for (const auto& [name, tag] : tables.names_3d)
    names += "N " + std::to_string(tag) + ' ' + name + '\n';
  for (const auto& [tag, name] : tables.tag_names_3d)
    names += "T " + std::to_string(tag) + ' ' + name + '\n';
  for (const auto& block : tables.unsupported) {
    rows.unsupported_entity.push_back(block.entity_tag);
    messages += block.message + '\n';
  }
  rows.names = bytes_of(names);
  rows.unsupported_messages = bytes_of(messages);
  return rows;
}

// The tables back from the datasets; false when they do not parse.
inline bool tables_from_rows(const TableRows& rows, GmshTables& tables) {
  if (rows.volumes.size() % 2 != 0) return false;
  for (std::size_t i = 0; i < rows.volumes.size(); i += 2)
    tables.volume_physicals[rows.volumes[i]].push_back(rows.volumes[i + 1]);
  std::istringstream names(std::string(rows.names.begin(), rows.names.end()));
  std::string line;
  while (std::getline(names, line)) {
    const std::size_t space = line.find(' ', 2);
    if (line.size() < 2 || (line[0] != 'N' && line[0] != 'T') || space == std::string::npos)
      return false;
    int tag = 0;
    try {
      tag = std::stoi(line.substr(2, space - 2));
    } catch (...) {
      return false;
    }
    const std::string name = line.substr(space + 1);
    if (line[0] == 'N')
      tables.names_3d.emplace(name, tag);
    else
      tables.tag_names_3d.emplace(tag, name);
  }
  std::istringstream messages(
      std::string(rows.unsupported_messages.begin(), rows.unsupported_messages.end()));
  for (std::int32_t entity : rows.unsupported_entity) {
    if (!std::getline(messages, line)) return false;
    tables.unsupported.push_back({entity, line});
  }
  return true;
}

}  // namespace fdem::model_file
