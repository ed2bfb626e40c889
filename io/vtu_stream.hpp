// A VTK XML unstructured grid (.vtu) or poly data (.vtp) written array by array, block by block:
// every array is asked for its tuples a block (~32 KiB) at a time, compressed with zlib and written
// at once, so a frame costs one block of memory instead of a copy of the mesh in VTK objects (for a
// jointed body that copy was ~0.6 kB per tet at the output peak).  The file is the one VTK's own
// writer makes (appended raw data, zlib blocks with a UInt64 header, legacy "0.1" cell offsets):
// VTK and ParaView read it unchanged.  The XML goes first with padded placeholders for the offsets,
// the data after it, and the offsets and block sizes are written back into their places at the end.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace fdem {

// One DataArray: `tuples` tuples of `components` values of VTK type `type` ("Float64", "Int64",
// "Int32", "UInt8"); fill(first, count, out) writes the bytes of tuples [first, first + count)
// (little endian, as the machine holds them) to `out`.
struct VtuArray {
  std::string name;
  const char* type = "Float64";
  int components = 1;
  std::size_t tuples = 0;
  std::function<void(std::size_t first, std::size_t count, unsigned char* out)> fill;
};

// The size in bytes of one value of VTK type `type`.
std::size_t vtu_value_bytes(const char* type);

// Points with their arrays, and cells as point indices with theirs.
struct VtuGrid {
  std::size_t points = 0, cells = 0;
  std::vector<VtuArray> point_data, cell_data;
  VtuArray positions;  // Float64 × 3 per point
  // Cell corners as point indices (Int64 × corners per cell: 4 in a .vtu, whose cells are tets;
  // 1 or 3 in a .vtp); offsets and types are derived.
  VtuArray corners;
};

// Writes `grid` to `path` with zlib at `level`.  Throws IoError ("cannot write <what> <path>:
// reason") on any failed write; a partial file is removed.
void write_vtu(const std::string& path, const VtuGrid& grid, int level, const std::string& what);

// The `.pvtu` summary of `pieces` (file names relative to it) with the arrays of `grid` (only
// their names, types and components are read).
std::string pvtu_summary(const VtuGrid& grid, const std::vector<std::string>& pieces);

// Poly data of one kind of cell: vertices (one point each: contact points) or triangles (crack
// faces).  Written as VTK's own poly-data writer does (appended raw zlib blocks, UInt64 headers).
struct VtpPolys : VtuGrid {
  enum class Cells { vertices, triangles };
  Cells kind = Cells::vertices;
};

void write_vtp(const std::string& path, const VtpPolys& polys, int level, const std::string& what);

// The `.pvtp` summary of `pieces` with the arrays of `polys`.
std::string pvtp_summary(const VtpPolys& polys, const std::vector<std::string>& pieces);

}  // namespace fdem
