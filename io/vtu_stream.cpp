#include "io/vtu_stream.hpp"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <sstream>

#include "core/error.hpp"

namespace fdem {

namespace {

// Uncompressed bytes per zlib block, as VTK's writer (a block is a whole number of tuples here,
// which the format allows: the block size is in each array's header).
constexpr std::size_t block_target_bytes = 32768;
constexpr int offset_width = 20;  // digits reserved for an offset (VTK pads the same way)
constexpr unsigned char vtk_tetra = 10;

class VtuFile {
 public:
  VtuFile(const std::string& path, std::string what) : path_(path), what_(std::move(what)) {
    errno = 0;
    file_ = std::fopen(path.c_str(), "wb");
    if (!file_) fail();
  }
  ~VtuFile() {
    if (file_) std::fclose(file_);
  }
  VtuFile(const VtuFile&) = delete;
  VtuFile& operator=(const VtuFile&) = delete;

  [[noreturn]] void fail() {
    const std::string reason = errno != 0 ? std::strerror(errno) : "disk full or no permission?";
    if (file_) std::fclose(file_);
    file_ = nullptr;
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
    throw IoError(what_ + ": " + reason);
  }
  void write(const void* data, std::size_t bytes) {
    if (bytes != 0 && std::fwrite(data, 1, bytes, file_) != bytes) fail();
  }
  void write(const std::string& text) { write(text.data(), text.size()); }
  std::int64_t tell() {
    const auto at = ftello(file_);
    if (at < 0) fail();
    return static_cast<std::int64_t>(at);
  }
  void seek(std::int64_t at) {
    if (fseeko(file_, static_cast<off_t>(at), SEEK_SET) != 0) fail();
  }
  void close() {
    const bool failed = std::fflush(file_) != 0 || std::ferror(file_) != 0;
    const bool closed = std::fclose(file_) == 0;
    file_ = nullptr;
    if (failed || !closed) fail();
  }

 private:
  std::string path_, what_;
  std::FILE* file_ = nullptr;
};

// The XML of one DataArray with a padded offset placeholder; `at` receives the placeholder's
// position in the file.
void data_array_xml(VtuFile& file, const VtuArray& a, bool show_components, std::int64_t& at,
                    const char* indent) {
  std::ostringstream xml;
  xml << indent << "<DataArray type=\"" << a.type << "\" Name=\"" << a.name << "\"";
  if (show_components && a.components != 1) xml << " NumberOfComponents=\"" << a.components << "\"";
  xml << " format=\"appended\" offset=\"";
  file.write(xml.str());
  at = file.tell();
  file.write(std::string(offset_width, ' ') + "\"/>\n");
}

// The array's tuples as zlib blocks after a UInt64 header [blocks, block bytes, bytes of a partial
// last block (0: the last is whole), compressed size of each block], as VTK's zlib compressor.
void write_compressed(VtuFile& file, const VtuArray& a, int level) {
  const std::size_t tuple_bytes = vtu_value_bytes(a.type) * static_cast<std::size_t>(a.components);
  const std::size_t tuples_per_block = std::max<std::size_t>(1, block_target_bytes / tuple_bytes);
  const std::size_t block_bytes = tuples_per_block * tuple_bytes;
  const std::size_t blocks = (a.tuples + tuples_per_block - 1) / tuples_per_block;
  std::vector<std::uint64_t> header(3 + blocks, 0);
  header[0] = blocks;
  header[1] = block_bytes;
  header[2] = (a.tuples % tuples_per_block) * tuple_bytes;
  const std::int64_t header_at = file.tell();
  file.write(header.data(), header.size() * sizeof(std::uint64_t));

  std::vector<unsigned char> raw(block_bytes), packed(compressBound(block_bytes));
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t first = b * tuples_per_block;
    const std::size_t count = std::min(tuples_per_block, a.tuples - first);
    a.fill(first, count, raw.data());
    uLongf packed_bytes = static_cast<uLongf>(packed.size());
    const int status = compress2(packed.data(), &packed_bytes, raw.data(),
                                 static_cast<uLong>(count * tuple_bytes), level);
    FDEM_VERIFY(status == Z_OK, "zlib compress2 of a frame block");
    file.write(packed.data(), packed_bytes);
    header[3 + b] = packed_bytes;
  }
  const std::int64_t end = file.tell();
  file.seek(header_at);
  file.write(header.data(), header.size() * sizeof(std::uint64_t));
  file.seek(end);
}

// The appended data of `order` (each array with the position of its offset placeholder), the end
// of the file, and every placeholder filled in.
void write_appended_data(VtuFile& file,
                         const std::vector<std::pair<const VtuArray*, std::int64_t>>& order,
                         int level) {
  file.write("  <AppendedData encoding=\"raw\">\n   _");
  const std::int64_t data_start = file.tell();
  std::vector<std::int64_t> offsets_in_data;
  for (const auto& [array, placeholder] : order) {
    offsets_in_data.push_back(file.tell() - data_start);
    write_compressed(file, *array, level);
  }
  file.write("\n  </AppendedData>\n</VTKFile>\n");
  for (std::size_t i = 0; i < order.size(); ++i) {
    file.seek(order[i].second);
    file.write(std::to_string(offsets_in_data[i]));
  }
  file.close();
}

// Cell offsets 1, 2, ... or 3, 6, ...: the end of each cell's corners.
VtuArray cell_offsets(std::size_t cells, int corners) {
  return {"offsets", "Int64", 1, cells,
          [corners](std::size_t first, std::size_t count, unsigned char* out) {
            for (std::size_t c = 0; c < count; ++c) {
              const std::int64_t end = corners * static_cast<std::int64_t>(first + c + 1);
              std::memcpy(out + 8 * c, &end, 8);
            }
          }};
}

std::string file_head(const char* type) {
  return std::string("<?xml version=\"1.0\"?>\n<VTKFile type=\"") + type +
         "\" version=\"0.1\" byte_order=\"LittleEndian\" header_type=\"UInt64\" "
         "compressor=\"vtkZLibDataCompressor\">\n";
}

// The summary (`type`: PUnstructuredGrid or PPolyData) of `pieces`, declaring the arrays' names,
// types and components.
std::string parallel_summary(const char* type, const VtuGrid& grid,
                             const std::vector<std::string>& pieces) {
  std::ostringstream xml;
  xml << file_head(type) << "  <" << type << " GhostLevel=\"0\">\n";
  const auto declare = [&](const VtuArray& a) {
    xml << "      <PDataArray type=\"" << a.type << "\" Name=\"" << a.name << "\"";
    if (a.components != 1) xml << " NumberOfComponents=\"" << a.components << "\"";
    xml << "/>\n";
  };
  xml << "    <PPointData>\n";
  for (const VtuArray& a : grid.point_data) declare(a);
  xml << "    </PPointData>\n    <PCellData>\n";
  for (const VtuArray& a : grid.cell_data) declare(a);
  xml << "    </PCellData>\n    <PPoints>\n";
  declare(grid.positions);
  xml << "    </PPoints>\n";
  for (const std::string& piece : pieces) xml << "    <Piece Source=\"" << piece << "\"/>\n";
  xml << "  </" << type << ">\n</VTKFile>\n";
  return xml.str();
}

// One piece of `type` (UnstructuredGrid or PolyData) with `piece_attributes` (its counts): the
// grid's point and cell arrays, its positions, and its cells in `cells_element` as the corners
// (connectivity, one tuple a cell, declared as one flat list) followed by `cell_arrays`.
void write_grid_file(const std::string& path, const std::string& what, int level, const char* type,
                     const std::string& piece_attributes, const VtuGrid& grid,
                     const char* cells_element,
                     std::initializer_list<const VtuArray*> cell_arrays) {
  VtuArray connectivity = grid.corners;
  connectivity.name = "connectivity";
  VtuFile file(path, what);
  file.write(file_head(type) + "  <" + type + ">\n    <Piece " + piece_attributes +
             ">\n      <PointData>\n");
  // Arrays in the order of the XML, each with the position of its offset placeholder.
  std::vector<std::pair<const VtuArray*, std::int64_t>> order;
  const auto declare = [&](const VtuArray& a, bool show_components) {
    order.emplace_back(&a, 0);
    data_array_xml(file, a, show_components, order.back().second, "        ");
  };
  for (const VtuArray& a : grid.point_data) declare(a, true);
  file.write("      </PointData>\n      <CellData>\n");
  for (const VtuArray& a : grid.cell_data) declare(a, true);
  file.write("      </CellData>\n      <Points>\n");
  declare(grid.positions, true);
  file.write(std::string("      </Points>\n      <") + cells_element + ">\n");
  declare(connectivity, false);
  for (const VtuArray* a : cell_arrays) declare(*a, false);
  file.write(std::string("      </") + cells_element + ">\n    </Piece>\n  </" + type + ">\n");
  write_appended_data(file, order, level);
}

}  // namespace

std::size_t vtu_value_bytes(const char* type) {
  const std::string t = type;
  if (t == "Float64" || t == "Int64") return 8;
  if (t == "Int32") return 4;
  FDEM_VERIFY(t == "UInt8", "vtu value type");
  return 1;
}

void write_vtu(const std::string& path, const VtuGrid& grid, int level, const std::string& what) {
  FDEM_VERIFY(grid.positions.tuples == grid.points && grid.corners.tuples == grid.cells,
              "vtu grid sizes");
  const VtuArray offsets = cell_offsets(grid.cells, 4);
  const VtuArray types{"types", "UInt8", 1, grid.cells,
                       [](std::size_t, std::size_t count, unsigned char* out) {
                         std::fill_n(out, count, vtk_tetra);
                       }};
  std::ostringstream piece;
  piece << "NumberOfPoints=\"" << grid.points << "\" NumberOfCells=\"" << grid.cells << "\"";
  write_grid_file(path, what, level, "UnstructuredGrid", piece.str(), grid, "Cells",
                  {&offsets, &types});
}

std::string pvtu_summary(const VtuGrid& grid, const std::vector<std::string>& pieces) {
  return parallel_summary("PUnstructuredGrid", grid, pieces);
}

void write_vtp(const std::string& path, const VtpPolys& polys, int level, const std::string& what) {
  const bool vertices = polys.kind == VtpPolys::Cells::vertices;
  const int corners = vertices ? 1 : 3;
  FDEM_VERIFY(polys.positions.tuples == polys.points && polys.corners.tuples == polys.cells &&
                  polys.corners.components == corners,
              "vtp poly data sizes");
  const VtuArray offsets = cell_offsets(polys.cells, corners);
  std::ostringstream piece;
  piece << "NumberOfPoints=\"" << polys.points << "\" NumberOfVerts=\""
        << (vertices ? polys.cells : 0) << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
        << "NumberOfPolys=\"" << (vertices ? 0 : polys.cells) << "\"";
  write_grid_file(path, what, level, "PolyData", piece.str(), polys, vertices ? "Verts" : "Polys",
                  {&offsets});
}

std::string pvtp_summary(const VtpPolys& polys, const std::vector<std::string>& pieces) {
  return parallel_summary("PPolyData", polys, pieces);
}

}  // namespace fdem
