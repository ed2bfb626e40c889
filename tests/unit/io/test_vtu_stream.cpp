// The streamed .vtu and .vtp writers against VTK: a grid whose arrays span several zlib blocks
// (whole and partial last blocks, every value type) is read back by VTK's reader bit for bit, and
// equals the same grid written by VTK's own writer.
#include <unistd.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkIdList.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkTypeInt64Array.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/vtu_stream.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;

namespace {

// 8192 points (Int64 gids: exactly two blocks of 4096) and 3000 tets (stress-like Float64 × 9: 7
// blocks, the last partial; Int32: one partial block).
constexpr std::size_t n_points = 8192, n_cells = 3000;

double coordinate(std::size_t p, int k) {
  return std::sin(0.37 * p + k) * (1.0 + 1e-3 * p);
}
std::int64_t point_gid(std::size_t p) {
  return (std::int64_t{1} << 40) + 7 * p;
}
std::int64_t corner(std::size_t c, int k) {
  return (5 * c + 1999 * k) % n_points;
}
double stress(std::size_t c, int k) {
  return 1e6 * std::cos(0.11 * c - k) + k;
}
std::int32_t piece(std::size_t c) {
  return static_cast<std::int32_t>(c % 17) - 3;
}

template <class Value>
fdem::VtuArray array(const char* name, const char* type, int components, std::size_t tuples,
                     Value (*value)(std::size_t, int)) {
  return {name, type, components, tuples,
          [value, components](std::size_t first, std::size_t count, unsigned char* out) {
            for (std::size_t t = 0; t < count; ++t)
              for (int k = 0; k < components; ++k) {
                const Value v = value(first + t, k);
                std::memcpy(out + (t * components + k) * sizeof(Value), &v, sizeof(Value));
              }
          }};
}

fdem::VtuGrid grid() {
  fdem::VtuGrid g;
  g.points = n_points;
  g.cells = n_cells;
  g.point_data.push_back(array<std::int64_t>("gid", "Int64", 1, n_points,
                                             [](std::size_t p, int) { return point_gid(p); }));
  g.cell_data.push_back(array<double>("stress", "Float64", 9, n_cells, stress));
  g.cell_data.push_back(array<std::int32_t>("piece", "Int32", 1, n_cells,
                                            [](std::size_t c, int) { return piece(c); }));
  g.positions = array<double>("Points", "Float64", 3, n_points, coordinate);
  g.corners = array<std::int64_t>("connectivity", "Int64", 4, n_cells, corner);
  return g;
}

// The same grid as a VTK object.
vtkNew<vtkUnstructuredGrid> vtk_grid() {
  vtkNew<vtkUnstructuredGrid> g;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n_points);
  for (std::size_t p = 0; p < n_points; ++p)
    points->SetPoint(p, coordinate(p, 0), coordinate(p, 1), coordinate(p, 2));
  g->SetPoints(points);
  g->Allocate(n_cells);
  for (std::size_t c = 0; c < n_cells; ++c) {
    const vtkIdType ids[4] = {corner(c, 0), corner(c, 1), corner(c, 2), corner(c, 3)};
    g->InsertNextCell(VTK_TETRA, 4, ids);
  }
  vtkNew<vtkTypeInt64Array> gid;
  gid->SetName("gid");
  for (std::size_t p = 0; p < n_points; ++p) gid->InsertNextValue(point_gid(p));
  g->GetPointData()->AddArray(gid);
  vtkNew<vtkDoubleArray> sigma;
  sigma->SetName("stress");
  sigma->SetNumberOfComponents(9);
  for (std::size_t c = 0; c < n_cells; ++c)
    for (int k = 0; k < 9; ++k) sigma->InsertNextValue(stress(c, k));
  g->GetCellData()->AddArray(sigma);
  vtkNew<vtkIntArray> pieces;
  pieces->SetName("piece");
  for (std::size_t c = 0; c < n_cells; ++c) pieces->InsertNextValue(piece(c));
  g->GetCellData()->AddArray(pieces);
  return g;
}

vtkSmartPointer<vtkUnstructuredGrid> read(const std::string& path) {
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  REQUIRE(reader->GetErrorCode() == 0);
  return reader->GetOutput();
}

std::string temp_dir() {
  std::string pattern = (fs::temp_directory_path() / "fdem_vtu_XXXXXX").string();
  REQUIRE(mkdtemp(pattern.data()));
  return pattern;
}

}  // namespace

TEST_CASE("a streamed .vtu reads back bit for bit and equals VTK's own writer's file",
          "[io][vtk]") {
  const std::string dir = temp_dir();
  const fdem::VtuGrid streamed = grid();
  fdem::write_vtu(dir + "/streamed.vtu", streamed, 1, "cannot write the test frame");
  {
    vtkNew<vtkXMLUnstructuredGridWriter> writer;
    writer->SetFileName((dir + "/vtk.vtu").c_str());
    writer->SetInputData(vtk_grid());
    writer->SetDataModeToAppended();
    writer->EncodeAppendedDataOff();
    writer->SetCompressionLevel(1);
    REQUIRE(writer->Write() == 1);
  }
  const auto ours = read(dir + "/streamed.vtu"), theirs = read(dir + "/vtk.vtu");
  for (vtkUnstructuredGrid* g : {ours.Get(), theirs.Get()}) {
    REQUIRE(g->GetNumberOfPoints() == static_cast<vtkIdType>(n_points));
    REQUIRE(g->GetNumberOfCells() == static_cast<vtkIdType>(n_cells));
    vtkDataArray* gid = g->GetPointData()->GetArray("gid");
    vtkDataArray* sigma = g->GetCellData()->GetArray("stress");
    vtkDataArray* pieces = g->GetCellData()->GetArray("piece");
    REQUIRE(gid);
    REQUIRE(sigma);
    REQUIRE(pieces);
    CHECK(gid->GetDataType() == VTK_LONG_LONG);
    CHECK(pieces->GetDataType() == VTK_INT);
    CHECK(sigma->GetNumberOfComponents() == 9);
    std::size_t wrong = 0;
    for (std::size_t p = 0; p < n_points; ++p) {
      double x[3];
      g->GetPoint(p, x);
      for (int k = 0; k < 3; ++k) wrong += x[k] != coordinate(p, k);
      wrong += static_cast<std::int64_t>(gid->GetComponent(p, 0)) != point_gid(p);
    }
    vtkNew<vtkIdList> ids;
    for (std::size_t c = 0; c < n_cells; ++c) {
      wrong += g->GetCellType(c) != VTK_TETRA;
      g->GetCellPoints(c, ids);
      wrong += ids->GetNumberOfIds() != 4;
      for (int k = 0; k < 4; ++k) wrong += ids->GetId(k) != corner(c, k);
      for (int k = 0; k < 9; ++k) wrong += sigma->GetComponent(c, k) != stress(c, k);
      wrong += pieces->GetComponent(c, 0) != piece(c);
    }
    CHECK(wrong == 0);
  }
  // Compressed alike: within a few per cent of VTK's file size (block sizes differ slightly).
  const double ratio = static_cast<double>(fs::file_size(dir + "/streamed.vtu")) /
                       static_cast<double>(fs::file_size(dir + "/vtk.vtu"));
  CHECK(ratio == Approx(1.0).margin(0.05));
  fs::remove_all(dir);
}

TEST_CASE("a .vtu that cannot be written: an IoError naming it, no file left", "[io][vtk]") {
  const std::string dir = temp_dir();
  const std::string path = dir + "/missing/frame.vtu";
  CHECK_THROWS_WITH(fdem::write_vtu(path, grid(), 1, "cannot write the frame " + path),
                    Contains("cannot write the frame " + path + ": No such file or directory"));
  CHECK_FALSE(fs::exists(path));
  fs::remove_all(dir);
}

namespace {

// Poly data: triangles over the same points (3 Int64 corners a cell: 1365 a block, 3000 cells in
// three blocks, the last partial), a per-triangle Float64 × 3 array; vertices one per point with
// a per-point Float64 × 3 array.
double cell_value(std::size_t c, int k) {
  return std::sin(0.013 * c * (k + 1)) * 1e3;
}

fdem::VtpPolys polys(fdem::VtpPolys::Cells kind) {
  fdem::VtpPolys p;
  p.kind = kind;
  p.points = n_points;
  p.positions = array<double>("Points", "Float64", 3, n_points, coordinate);
  if (kind == fdem::VtpPolys::Cells::triangles) {
    p.cells = n_cells;
    p.corners = array<std::int64_t>("connectivity", "Int64", 3, n_cells, corner);
    p.cell_data.push_back(array<double>("traction", "Float64", 3, n_cells, cell_value));
  } else {
    p.cells = n_points;
    p.corners = array<std::int64_t>("connectivity", "Int64", 1, n_points,
                                    [](std::size_t v, int) { return std::int64_t(v); });
    p.point_data.push_back(array<double>("force", "Float64", 3, n_points, cell_value));
  }
  return p;
}

// How many values of the poly data read from `path` differ from polys(kind).
std::size_t wrong_values(const std::string& path, fdem::VtpPolys::Cells kind) {
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  REQUIRE(reader->GetErrorCode() == 0);
  vtkPolyData* p = reader->GetOutput();
  const bool triangles = kind == fdem::VtpPolys::Cells::triangles;
  REQUIRE(p->GetNumberOfPoints() == static_cast<vtkIdType>(n_points));
  REQUIRE(p->GetNumberOfCells() == static_cast<vtkIdType>(triangles ? n_cells : n_points));
  REQUIRE(p->GetNumberOfPolys() == (triangles ? static_cast<vtkIdType>(n_cells) : 0));
  REQUIRE(p->GetNumberOfVerts() == (triangles ? 0 : static_cast<vtkIdType>(n_points)));
  vtkDataArray* values =
      triangles ? p->GetCellData()->GetArray("traction") : p->GetPointData()->GetArray("force");
  REQUIRE(values);
  REQUIRE(values->GetNumberOfComponents() == 3);
  std::size_t wrong = 0;
  for (std::size_t q = 0; q < n_points; ++q) {
    double x[3];
    p->GetPoint(q, x);
    for (int k = 0; k < 3; ++k) wrong += x[k] != coordinate(q, k);
  }
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < p->GetNumberOfCells(); ++c) {
    p->GetCellPoints(c, ids);
    wrong += ids->GetNumberOfIds() != (triangles ? 3 : 1);
    for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k)
      wrong += ids->GetId(k) != (triangles ? corner(c, k) : c);
    for (int k = 0; k < 3; ++k) wrong += values->GetComponent(c, k) != cell_value(c, k);
  }
  return wrong;
}

}  // namespace

TEST_CASE("a streamed .vtp of triangles or of vertices reads back bit for bit with VTK's reader",
          "[io][vtk]") {
  const std::string dir = temp_dir();
  for (const auto kind : {fdem::VtpPolys::Cells::triangles, fdem::VtpPolys::Cells::vertices}) {
    const std::string path = dir + "/streamed.vtp";
    fdem::write_vtp(path, polys(kind), 1, "cannot write the test frame");
    CHECK(wrong_values(path, kind) == 0);
  }
  // An empty piece (as a rank without contacts writes): zero points and cells, same arrays.
  fdem::VtpPolys empty = polys(fdem::VtpPolys::Cells::vertices);
  empty.points = empty.cells = empty.positions.tuples = empty.corners.tuples = 0;
  empty.point_data[0].tuples = 0;
  fdem::write_vtp(dir + "/empty.vtp", empty, 1, "cannot write the test frame");
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName((dir + "/empty.vtp").c_str());
  reader->Update();
  CHECK(reader->GetErrorCode() == 0);
  CHECK(reader->GetOutput()->GetNumberOfPoints() == 0);
  CHECK(reader->GetOutput()->GetPointData()->GetArray("force") != nullptr);
  // A .vtp that cannot be written: an IoError naming it, no file left.
  const std::string missing = dir + "/missing/frame.vtp";
  CHECK_THROWS_WITH(fdem::write_vtp(missing, polys(fdem::VtpPolys::Cells::vertices), 1,
                                    "cannot write the frame " + missing),
                    Contains("cannot write the frame " + missing + ": No such file or directory"));
  CHECK_FALSE(fs::exists(missing));
  fs::remove_all(dir);
}
