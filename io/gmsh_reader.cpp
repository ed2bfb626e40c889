// Gmsh MSH 4.1 reader.  Layout reference: Gmsh reference manual, section "MSH file format".
// The whole file is read into memory; one cursor walks it, reading ASCII tokens or raw binary
// values, and knows how to turn a position into "line N" (ASCII) or "byte offset N" (binary).
#include "io/gmsh_reader.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <string_view>
#include <system_error>
#include <unordered_map>

#include "core/error.hpp"

namespace fdem {
namespace {

constexpr int kLinearTet = 4;

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

// Printable excerpt of what was found, for messages.
std::string excerpt(std::string_view text) {
  constexpr std::size_t kMax = 40;
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < kMax; ++i) {
    const unsigned char ch = static_cast<unsigned char>(text[i]);
    out += std::isprint(ch) ? static_cast<char>(ch) : '?';
  }
  if (text.size() > kMax) out += "...";
  return out;
}

std::string read_whole_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    throw InputError("Gmsh mesh file '" + path +
                     "' does not exist (relative paths are taken from " +
                     fs::current_path(ec).string() + "); expected an MSH 4.1 file from Gmsh.");
  }
  if (fs::is_directory(path, ec)) {
    throw InputError("Gmsh mesh file '" + path + "' is a directory; expected an MSH 4.1 file.");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw InputError("Gmsh mesh file '" + path +
                     "' exists but cannot be opened for reading (check its permissions).");
  }
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  std::string data(size > 0 ? static_cast<std::size_t>(size) : 0, '\0');
  if (size < 0 || !in.read(data.data(), size)) {
    throw InputError("Gmsh mesh file '" + path + "' could not be read (I/O error).");
  }
  return data;
}

// Walks the file.  ascii_* always read text (headers, $PhysicalNames); read_* read text or raw
// binary values according to the file type.
class MshCursor {
 public:
  MshCursor(const std::string& path, const std::string& data) : path_(path), data_(data) {}

  bool binary = false;  // set once $MeshFormat says "4.1 1 8"
  std::string section;  // e.g. "$Nodes", for messages

  std::size_t pos() const { return pos_; }
  bool at_end() const { return pos_ >= data_.size(); }
  std::size_t remaining() const { return data_.size() - pos_; }

  std::string location(std::size_t at) const {
    if (binary) return "byte offset " + std::to_string(at);
    return "line " + std::to_string(line_of(at));
  }

  [[noreturn]] void fail_at(std::size_t at, const std::string& what) const {
    throw InputError("Gmsh file '" + path_ + "', " + location(at) +
                     (section.empty() ? "" : " (in " + section + ")") + ": " + what);
  }

  [[noreturn]] void fail_truncated(std::size_t at, const std::string& what) const {
    fail_at(at, "unexpected end of file while reading " + what +
                    "; the file is truncated (incomplete copy or interrupted export?), re-export "
                    "it from Gmsh.");
  }

  void skip_space() {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
  }

  // Rest of the current line (without '\r' and trailing blanks); moves past the newline.
  std::string_view line() {
    const std::size_t start = pos_;
    std::size_t end = data_.find('\n', start);
    if (end == std::string::npos) end = data_.size();
    pos_ = std::min(end + 1, data_.size());
    std::size_t last = end;
    while (last > start && std::isspace(static_cast<unsigned char>(data_[last - 1]))) --last;
    return std::string_view(data_).substr(start, last - start);
  }

  // Skips to just past the next newline (end of a header line before binary data).
  void skip_rest_of_line() { pos_ = std::min(data_.find('\n', pos_), data_.size() - 1) + 1; }

  std::string_view ascii_token(const std::string& what) {
    skip_space();
    if (at_end()) fail_truncated(data_.size(), what);
    token_start_ = pos_;
    while (pos_ < data_.size() && !std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    return std::string_view(data_).substr(token_start_, pos_ - token_start_);
  }

  std::int64_t ascii_int(const std::string& what) {
    const std::string_view token = ascii_token(what);
    std::int64_t value = 0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || end != token.data() + token.size()) {
      fail_at(token_start_, "expected " + what + " (an integer), found '" + excerpt(token) + "'.");
    }
    return value;
  }

  // A double-quoted name, as in $PhysicalNames.
  std::string ascii_quoted(const std::string& what) {
    skip_space();
    if (at_end()) fail_truncated(data_.size(), what);
    const std::size_t start = pos_;
    const std::size_t line_end = std::min(data_.find('\n', start), data_.size());
    const std::size_t close = data_[start] == '"' ? data_.find('"', start + 1) : std::string::npos;
    if (close == std::string::npos || close > line_end) {
      fail_at(start, "expected " + what + " in double quotes, found '" +
                         excerpt(std::string_view(data_).substr(start, line_end - start)) + "'.");
    }
    pos_ = close + 1;
    return data_.substr(start + 1, close - start - 1);
  }

  // Position where the last value read started (for messages about that value).
  std::size_t value_start() const { return token_start_; }

  template <class T>
  T raw(const std::string& what) {
    if (remaining() < sizeof(T)) {
      fail_truncated(pos_, what + " (" + std::to_string(sizeof(T)) + " bytes, only " +
                               std::to_string(remaining()) + " left)");
    }
    token_start_ = pos_;
    T value;
    std::memcpy(&value, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }

  // A non-negative count or tag: size_t in binary files.
  std::int64_t read_size(const std::string& what) {
    if (binary) {
      const std::uint64_t value = raw<std::uint64_t>(what);
      if (value > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
        fail_at(token_start_, "expected " + what + ", found the impossible value " +
                                  std::to_string(value) + "; the file is damaged.");
      }
      return static_cast<std::int64_t>(value);
    }
    const std::int64_t value = ascii_int(what);
    if (value < 0) {
      fail_at(token_start_, "expected " + what + " (a non-negative integer), found " +
                                std::to_string(value) + ".");
    }
    return value;
  }

  // An 'int' field (entity dimensions and tags, element types, physical tags).
  int read_int(const std::string& what) {
    if (binary) return raw<std::int32_t>(what);
    const std::int64_t value = ascii_int(what);
    if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max()) {
      fail_at(token_start_,
              "expected " + what + " (a 32-bit integer), found " + std::to_string(value) + ".");
    }
    return static_cast<int>(value);
  }

  double read_double(const std::string& what) {
    double value = 0.0;
    if (binary) {
      value = raw<double>(what);
    } else {
      const std::string_view token = ascii_token(what);
      const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
      if (ec != std::errc() || end != token.data() + token.size()) {
        fail_at(token_start_, "expected " + what + " (a number), found '" + excerpt(token) + "'.");
      }
    }
    if (!std::isfinite(value))
      fail_at(token_start_, "expected " + what + ", found NaN or infinity.");
    return value;
  }

  // Refuses counts that cannot fit in the rest of the file (damaged or truncated file), before
  // anything is allocated for them.  min_bytes: smallest size of one item (binary layout).
  void check_count(std::int64_t count, std::size_t min_bytes, const std::string& what) {
    const std::size_t bytes_each = binary ? min_bytes : 2;  // ASCII: a digit and a separator
    if (count > 0 && static_cast<std::uint64_t>(count) > remaining() / bytes_each) {
      fail_at(data_.size(), "unexpected end of file: " + std::to_string(count) + " " + what +
                                " are announced, which need at least " +
                                std::to_string(static_cast<std::uint64_t>(count) * bytes_each) +
                                " bytes, but only " + std::to_string(remaining()) +
                                " remain; the file is truncated (incomplete copy or interrupted "
                                "export?), re-export it from Gmsh.");
    }
  }

  void skip_bytes(std::size_t bytes, const std::string& what) {
    if (remaining() < bytes) fail_truncated(pos_, what);
    pos_ += bytes;
  }

  void expect_end(const std::string& name) {
    skip_space();
    if (at_end()) fail_truncated(data_.size(), "'$End" + name + "'");
    const std::size_t start = pos_;
    const std::string_view found = line();
    if (found != "$End" + name) {
      fail_at(start, "expected '$End" + name +
                         "' (the counts in the section header do not match "
                         "its content), found '" +
                         excerpt(found) + "'.");
    }
  }

  // Skips a section this reader does not use, up to and including its end marker.
  void skip_section(const std::string& name, std::size_t start) {
    const std::string marker = "\n$End" + name;
    const std::size_t found = data_.find(marker, pos_ > 0 ? pos_ - 1 : 0);
    if (found == std::string::npos) {
      fail_at(start, "section '$" + name + "' has no '$End" + name +
                         "' marker; the file is truncated or damaged.");
    }
    pos_ = found + 1;
    line();
  }

 private:
  std::size_t line_of(std::size_t at) const {
    at = std::min(at, data_.size());
    // End of file just after a final newline still belongs to the last line.
    if (at == data_.size() && at > 0 && data_[at - 1] == '\n') --at;
    return 1 + static_cast<std::size_t>(std::count(data_.begin(), data_.begin() + at, '\n'));
  }

  const std::string& path_;
  const std::string& data_;
  std::size_t pos_ = 0;
  std::size_t token_start_ = 0;
};

// Node tag -> index into the node arrays: a dense table when tags are compact, a hash otherwise.
class NodeIndex {
 public:
  void reserve(std::int64_t min_tag, std::int64_t max_tag, std::int64_t count) {
    min_tag_ = min_tag;
    const std::int64_t span = max_tag - min_tag + 1;
    dense_ = count > 0 && max_tag >= min_tag && span <= 4 * count + 1024;
    if (dense_) {
      table_.assign(static_cast<std::size_t>(span), -1);
    } else {
      map_.reserve(static_cast<std::size_t>(count));
    }
  }
  // Returns false if the tag was already present.
  bool insert(std::int64_t tag, std::int64_t index) {
    if (dense_ && tag >= min_tag_ && tag - min_tag_ < static_cast<std::int64_t>(table_.size())) {
      std::int64_t& slot = table_[static_cast<std::size_t>(tag - min_tag_)];
      if (slot >= 0) return false;
      slot = index;
      return true;
    }
    return map_.emplace(tag, index).second;  // also takes tags outside the announced range
  }
  std::int64_t find(std::int64_t tag) const {
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

// A block of volume elements fdem cannot use; an error if its entity is kept.
struct UnsupportedBlock {
  int entity_tag;
  std::string message;
};

struct RawMesh {
  std::map<std::string, int> names_3d;  // $PhysicalNames, dimension 3
  std::map<int, std::string> tag_names_3d;
  std::map<int, std::vector<int>> volume_physicals;  // volume entity tag -> physical tags
  bool have_nodes = false;
  bool have_elements = false;
  NodeIndex node_index;
  std::vector<std::int64_t> node_tags;  // all nodes of the file
  std::vector<double> node_xyz;
  std::vector<std::int64_t> tet_nodes;  // 4 per tet, indices into node_tags
  std::vector<std::int64_t> tet_tags;
  std::vector<int> tet_entity;  // volume entity tag of each tet
  std::vector<UnsupportedBlock> unsupported;
};

void read_mesh_format(MshCursor& cur, const std::string& path) {
  cur.skip_space();
  if (cur.at_end()) {
    cur.fail_at(0, "the file is empty; expected a Gmsh mesh starting with '$MeshFormat'.");
  }
  const std::size_t first_start = cur.pos();
  const std::string_view first = cur.line();
  if (first != "$MeshFormat") {
    cur.fail_at(first_start,
                "not a Gmsh mesh file: expected '$MeshFormat' as the first line, found '" +
                    excerpt(first) + "'. fdem reads meshes written by Gmsh in MSH 4.1 format.");
  }
  cur.section = "$MeshFormat";
  const std::string version(cur.ascii_token("the format version"));
  const std::size_t version_start = cur.value_start();
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

void read_physical_names(MshCursor& cur, RawMesh& mesh) {
  // Always ASCII, even in binary files.
  const std::int64_t count = cur.ascii_int("the number of physical names");
  for (std::int64_t i = 0; i < count; ++i) {
    const std::int64_t dim = cur.ascii_int("a physical group dimension (0-3)");
    const std::int64_t tag = cur.ascii_int("a physical group tag");
    const std::string name = cur.ascii_quoted("a physical group name");
    if (dim == 3) {
      mesh.names_3d.emplace(name, static_cast<int>(tag));
      mesh.tag_names_3d.emplace(static_cast<int>(tag), name);
    }
  }
  cur.expect_end("PhysicalNames");
}

void read_entities(MshCursor& cur, RawMesh& mesh) {
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
    }
  }
  cur.expect_end("Entities");
}

void read_nodes(MshCursor& cur, RawMesh& mesh) {
  const std::int64_t num_blocks = cur.read_size("the number of node blocks");
  const std::int64_t num_nodes = cur.read_size("the number of nodes");
  const std::int64_t min_tag = cur.read_size("the smallest node tag");
  const std::int64_t max_tag = cur.read_size("the largest node tag");
  cur.check_count(num_blocks, 3 * 4 + 8, "node blocks");
  cur.check_count(num_nodes, 8 + 3 * 8, "nodes");
  mesh.node_index.reserve(min_tag, max_tag, num_nodes);
  mesh.node_tags.reserve(static_cast<std::size_t>(num_nodes));
  mesh.node_xyz.reserve(3 * static_cast<std::size_t>(num_nodes));

  std::vector<std::size_t> tag_positions;
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

    const std::size_t first = mesh.node_tags.size();
    tag_positions.clear();
    for (std::int64_t i = 0; i < count; ++i) {
      const std::int64_t tag = cur.read_size("a node tag");
      tag_positions.push_back(cur.value_start());
      mesh.node_tags.push_back(tag);
    }
    for (std::int64_t i = 0; i < count; ++i) {
      for (int k = 0; k < 3; ++k) mesh.node_xyz.push_back(cur.read_double("a node coordinate"));
      for (int k = 3; k < values_per_node; ++k) cur.read_double("a parametric node coordinate");
    }
    for (std::int64_t i = 0; i < count; ++i) {
      const std::size_t index = first + static_cast<std::size_t>(i);
      if (!mesh.node_index.insert(mesh.node_tags[index], static_cast<std::int64_t>(index))) {
        cur.fail_at(tag_positions[static_cast<std::size_t>(i)],
                    "node tag " + std::to_string(mesh.node_tags[index]) +
                        " is defined twice; node tags must be unique.");
      }
    }
  }
  if (static_cast<std::int64_t>(mesh.node_tags.size()) != num_nodes) {
    cur.fail_at(cur.pos(), "the section header announces " + std::to_string(num_nodes) +
                               " nodes but its blocks hold " +
                               std::to_string(mesh.node_tags.size()) + "; the file is damaged.");
  }
  cur.expect_end("Nodes");
  mesh.have_nodes = true;
}

void read_elements(MshCursor& cur, RawMesh& mesh) {
  const std::int64_t num_blocks = cur.read_size("the number of element blocks");
  const std::int64_t num_elements = cur.read_size("the number of elements");
  cur.read_size("the smallest element tag");
  cur.read_size("the largest element tag");
  cur.check_count(num_blocks, 3 * 4 + 8, "element blocks");
  cur.check_count(num_elements, 2 * 8, "elements");

  std::int64_t total = 0;
  for (std::int64_t b = 0; b < num_blocks; ++b) {
    const int entity_dim = cur.read_int("the entity dimension of an element block");
    const std::size_t block_start = cur.value_start();
    const int entity_tag = cur.read_int("the entity tag of an element block");
    const int type = cur.read_int("the element type");
    const std::size_t type_start = cur.value_start();
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
        for (int k = 0; k < 4; ++k) {
          const std::int64_t node_tag =
              cur.read_size("a node tag of tetrahedron " + std::to_string(tag));
          const std::int64_t index = mesh.node_index.find(node_tag);
          if (index < 0) {
            cur.fail_at(cur.value_start(), "tetrahedron " + std::to_string(tag) +
                                               " references node tag " + std::to_string(node_tag) +
                                               ", which is not defined in $Nodes.");
          }
          mesh.tet_nodes.push_back(index);
        }
        mesh.tet_tags.push_back(tag);
        mesh.tet_entity.push_back(entity_dim == 3 ? entity_tag : -1);
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
    const std::size_t values = static_cast<std::size_t>(count) * (1 + info->num_nodes);
    if (cur.binary) {
      cur.skip_bytes(values * 8, std::string("elements of type ") + info->name);
    } else {
      for (std::size_t v = 0; v < values; ++v) {
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
  mesh.have_elements = true;
}

std::string list_groups(const RawMesh& mesh) {
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

GmshMesh read_gmsh(const std::string& path, const std::string& physical) {
  return parse_gmsh(read_whole_file(path), path, physical);
}

GmshMesh parse_gmsh(const std::string& data, const std::string& path, const std::string& physical) {
  MshCursor cur(path, data);
  RawMesh mesh;

  read_mesh_format(cur, path);
  while (true) {
    cur.section.clear();
    cur.skip_space();
    if (cur.at_end()) break;
    const std::size_t start = cur.pos();
    const std::string_view header = cur.line();
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
      if (mesh.have_nodes) cur.fail_at(start, "a second '$Nodes' section; the file is damaged.");
      read_nodes(cur, mesh);
    } else if (name == "Elements") {
      if (!mesh.have_nodes) {
        cur.fail_at(start, "'$Elements' comes before '$Nodes'; expected $Nodes first.");
      }
      if (mesh.have_elements) {
        cur.fail_at(start, "a second '$Elements' section; the file is damaged.");
      }
      read_elements(cur, mesh);
    } else {
      cur.skip_section(name, start);  // $Periodic, $NodeData, $Comments, $PartitionedEntities...
    }
  }
  cur.section.clear();
  const std::string file = "Gmsh file '" + path + "'";

  // Physical filter: a 3D group name, else a 3D group number.
  int filter_tag = 0;
  std::string filter_label;
  if (!physical.empty()) {
    const auto by_name = mesh.names_3d.find(physical);
    if (by_name != mesh.names_3d.end()) {
      filter_tag = by_name->second;
    } else {
      int number = 0;
      const auto [end, ec] =
          std::from_chars(physical.data(), physical.data() + physical.size(), number);
      const bool is_number = ec == std::errc() && end == physical.data() + physical.size();
      bool known = is_number && mesh.tag_names_3d.count(number) > 0;
      for (const auto& entry : mesh.volume_physicals) {
        const std::vector<int>& tags = entry.second;
        known = known || (is_number && std::find(tags.begin(), tags.end(), number) != tags.end());
      }
      if (!known) {
        throw InputError(file + ": no 3D physical group named or numbered '" + physical + "'; " +
                         list_groups(mesh) + ".");
      }
      filter_tag = number;
    }
    filter_label = "'" + physical + "' (tag " + std::to_string(filter_tag) + ")";
  }
  const auto entity_kept = [&](int entity_tag) {
    if (filter_tag == 0) return true;
    const auto it = mesh.volume_physicals.find(entity_tag);
    return it != mesh.volume_physicals.end() &&
           std::find(it->second.begin(), it->second.end(), filter_tag) != it->second.end();
  };

  for (const UnsupportedBlock& block : mesh.unsupported) {
    if (entity_kept(block.entity_tag)) throw InputError(file + ", " + block.message);
  }
  if (mesh.tet_tags.empty()) {
    throw InputError(file +
                     " contains no 4-node tetrahedra (element type 4); expected a 3D mesh. The "
                     "file may be a surface mesh: mesh it in 3D with `gmsh -3 your_model.geo`.");
  }

  GmshMesh out;
  out.physical_names = mesh.names_3d;
  std::vector<std::int64_t> new_index(mesh.node_tags.size(), -1);
  for (std::size_t t = 0; t < mesh.tet_tags.size(); ++t) {
    const int entity = mesh.tet_entity[t];
    if (!entity_kept(entity)) continue;
    int tet_physical = filter_tag;
    if (filter_tag == 0) {
      const auto it = mesh.volume_physicals.find(entity);
      if (it != mesh.volume_physicals.end() && !it->second.empty()) tet_physical = it->second[0];
    }
    out.tet_tags.push_back(mesh.tet_tags[t]);
    out.tet_physical.push_back(tet_physical);
    for (int k = 0; k < 4; ++k) new_index[static_cast<std::size_t>(mesh.tet_nodes[4 * t + k])] = 0;
  }
  if (out.tet_tags.empty()) {
    throw InputError(file + ": the 3D physical group " + filter_label +
                     " exists but contains no 4-node tetrahedra (its volumes were not meshed, or "
                     "the group lists no volume); the file's " +
                     std::to_string(mesh.tet_tags.size()) + " tetrahedra lie in other groups; " +
                     list_groups(mesh) + ".");
  }

  // Keep used nodes in file order.
  std::int64_t next = 0;
  for (std::size_t i = 0; i < new_index.size(); ++i) {
    if (new_index[i] < 0) continue;
    new_index[i] = next++;
    out.node_tags.push_back(mesh.node_tags[i]);
    out.coords.insert(out.coords.end(), mesh.node_xyz.begin() + 3 * i,
                      mesh.node_xyz.begin() + 3 * i + 3);
  }
  if (next > std::numeric_limits<std::int32_t>::max()) {
    throw InputError(file + ": " + std::to_string(next) +
                     " nodes exceed the 2^31-1 nodes one mesh file may have in fdem; split the "
                     "model into several bodies.");
  }
  out.tets.reserve(4 * out.tet_tags.size());
  for (std::size_t t = 0; t < mesh.tet_tags.size(); ++t) {
    if (!entity_kept(mesh.tet_entity[t])) continue;
    for (int k = 0; k < 4; ++k) {
      out.tets.push_back(static_cast<std::int32_t>(
          new_index[static_cast<std::size_t>(mesh.tet_nodes[4 * t + k])]));
    }
  }
  return out;
}

}  // namespace fdem
