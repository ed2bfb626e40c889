#include "io/vtk_output.hpp"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkTypeInt64Array.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPPolyDataWriter.h>
#include <vtkXMLPUnstructuredGridWriter.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "core/error.hpp"

namespace fdem {

namespace {

// Removes a partial file, keeping errno (the reason the write failed) for the message.
void remove_partial(const std::string& path) {
  const int saved = errno;
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
  errno = saved;
}

std::string system_reason() {
  return errno != 0 ? std::strerror(errno) : "disk full or no permission?";
}

}  // namespace

void write_file_atomically(const std::string& path, const std::string& content) {
  const std::string tmp = path + ".tmp";
  errno = 0;
  std::ofstream out(tmp, std::ios::binary);
  out << content;
  out.close();  // the last bytes reach the disk here: check after closing
  if (!out) {
    const std::string reason = system_reason();
    remove_partial(tmp);
    throw IoError("cannot write " + path + ": " + reason);
  }
  std::error_code error;
  std::filesystem::rename(tmp, path, error);
  if (error) {
    remove_partial(tmp);
    throw IoError("cannot rename " + tmp + " to " + path + ": " + error.message());
  }
}

std::string frame_file_name(const std::string& stem, const std::string& extension, int ranks) {
  return stem + (ranks > 1 ? ".p" : ".") + extension;
}

std::string frame_piece_name(const std::string& stem, const std::string& extension, int rank) {
  return stem + "_" + std::to_string(rank) + "." + extension;
}

SeriesWriter::SeriesWriter(std::string directory, std::string series, int rank, int ranks)
    : directory_(std::move(directory)), series_(std::move(series)), rank_(rank), ranks_(ranks) {
  FDEM_VERIFY(ranks_ >= 1 && rank_ >= 0 && rank_ < ranks_, "series writer rank");
  std::filesystem::create_directories(std::filesystem::path(directory_) / series_);
}

std::string SeriesWriter::next_frame_path() const {
  std::ostringstream name;
  name << series_ << "/" << series_ << "_" << std::setw(6) << std::setfill('0') << entries_.size();
  return name.str();
}

void SeriesWriter::add_frame(double time, const std::string& relative_path) {
  entries_.emplace_back(time, relative_path);
  if (rank_ == 0) write_pvd();
}

void SeriesWriter::write_pvd() const {
  std::ostringstream xml;
  xml << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" "
         "byte_order=\"LittleEndian\">\n"
      << "  <Collection>\n";
  xml << std::setprecision(17);
  for (const auto& [time, file] : entries_)
    xml << "    <DataSet timestep=\"" << time << "\" group=\"\" part=\"0\" file=\"" << file
        << "\"/>\n";
  xml << "  </Collection>\n</VTKFile>\n";
  write_file_atomically((std::filesystem::path(directory_) / (series_ + ".pvd")).string(),
                        xml.str());
}

namespace {

// zlib level of the frames' arrays: 1 is the fastest.  Measured on the jointed bricks (11,520
// tets, two frames): the output stage took a third of its time at zlib's default level (6),
// 0.47 → 0.155 s, for frames 10–25 % larger (1.51 → 1.66 MB).
constexpr int frame_compression_level = 1;

vtkNew<vtkDoubleArray> make_array(const std::string& name, int components, vtkIdType tuples) {
  vtkNew<vtkDoubleArray> a;
  a->SetName(name.c_str());
  a->SetNumberOfComponents(components);
  a->SetNumberOfTuples(tuples);
  return a;
}

vtkNew<vtkDoubleArray> full_array(const FrameField& f, vtkIdType tuples, const char* what) {
  FDEM_VERIFY(static_cast<vtkIdType>(f.values.size()) == tuples * f.components, what);
  auto a = make_array(f.name, f.components, tuples);
  for (vtkIdType i = 0; i < tuples * f.components; ++i) a->SetValue(i, f.values[i]);
  return a;
}

template <class Array, class Value>
vtkSmartPointer<vtkDataArray> typed_array(const FrameArray& f, const std::vector<Value>& values) {
  auto a = vtkSmartPointer<Array>::New();
  a->SetName(f.name.c_str());
  a->SetNumberOfComponents(f.components);
  a->SetNumberOfTuples(static_cast<vtkIdType>(values.size() / f.components));
  for (std::size_t i = 0; i < values.size(); ++i) a->SetValue(static_cast<vtkIdType>(i), values[i]);
  return a;
}

// A frame array as a VTK array of its type: f64 → Float64, i64 → Int64, i32 → Int32.
vtkSmartPointer<vtkDataArray> vtk_array(const FrameArray& f) {
  if (f.type == FrameValue::f64) return typed_array<vtkDoubleArray>(f, f.real);
  if (f.type == FrameValue::i64) return typed_array<vtkTypeInt64Array>(f, f.integer);
  return typed_array<vtkIntArray>(f, f.integer);
}

// The owned tets of `model` and the nodes they reference, renumbered in ascending local order
// (on one rank with every node in a tet, the identity).
vtkSmartPointer<vtkUnstructuredGrid> owned_tet_grid(const Model& model,
                                                    const std::vector<std::string>& fields,
                                                    const std::vector<FrameField>& extra) {
  const NodeArrays& nodes = model.nodes;
  const TetArrays& tets = model.tets;
  const std::vector<LocalIndex> cells = owned_tets(tets);  // ascending, so ascending gid
  std::vector<LocalIndex> renumbered(nodes.size(), -1);
  for (const LocalIndex t : cells)
    for (int c = 0; c < 4; ++c) renumbered[tets.nodes[4 * t + c]] = 0;
  std::vector<LocalIndex> points;  // local nodes written, ascending
  for (LocalIndex i = 0; i < nodes.size(); ++i)
    if (renumbered[i] == 0) {
      renumbered[i] = static_cast<LocalIndex>(points.size());
      points.push_back(i);
    }
  const vtkIdType n_points = static_cast<vtkIdType>(points.size());
  const vtkIdType n_cells = static_cast<vtkIdType>(cells.size());

  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  vtkNew<vtkPoints> xyz;
  xyz->SetDataTypeToDouble();
  xyz->SetNumberOfPoints(n_points);
  for (vtkIdType p = 0; p < n_points; ++p) xyz->SetPoint(p, &nodes.x[3 * points[p]]);
  grid->SetPoints(xyz);
  grid->Allocate(n_cells);
  for (const LocalIndex t : cells) {
    const vtkIdType ids[4] = {renumbered[tets.nodes[4 * t]], renumbered[tets.nodes[4 * t + 1]],
                              renumbered[tets.nodes[4 * t + 2]], renumbered[tets.nodes[4 * t + 3]]};
    grid->InsertNextCell(VTK_TETRA, 4, ids);
  }
  // One frame array at a time, freed once copied: the frame's peak holds the VTK arrays only.
  for_each_tet_frame_array(model, cells, points, fields, extra, [&](FrameArray& f) {
    if (f.per_cell)
      grid->GetCellData()->AddArray(vtk_array(f));
    else
      grid->GetPointData()->AddArray(vtk_array(f));
  });
  return grid;
}

vtkSmartPointer<vtkPolyData> point_poly(const std::vector<double>& points,
                                        const std::vector<FrameField>& point_fields) {
  const vtkIdType n = static_cast<vtkIdType>(points.size() / 3);
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(n);
  vtkNew<vtkCellArray> verts;
  for (vtkIdType i = 0; i < n; ++i) {
    pts->SetPoint(i, &points[3 * i]);
    verts->InsertNextCell(1, &i);
  }
  poly->SetPoints(pts);
  poly->SetVerts(verts);
  for (const FrameField& f : point_fields)
    poly->GetPointData()->AddArray(full_array(f, n, "point field size"));
  return poly;
}

vtkSmartPointer<vtkPolyData> triangle_poly(const std::vector<double>& points,
                                           const std::vector<std::int64_t>& triangles,
                                           const std::vector<FrameField>& cell_fields) {
  const vtkIdType n_points = static_cast<vtkIdType>(points.size() / 3);
  const vtkIdType n_cells = static_cast<vtkIdType>(triangles.size() / 3);
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(n_points);
  for (vtkIdType i = 0; i < n_points; ++i) pts->SetPoint(i, &points[3 * i]);
  vtkNew<vtkCellArray> polys;
  for (vtkIdType t = 0; t < n_cells; ++t) {
    const vtkIdType ids[3] = {triangles[3 * t], triangles[3 * t + 1], triangles[3 * t + 2]};
    polys->InsertNextCell(3, ids);
  }
  poly->SetPoints(pts);
  poly->SetPolys(polys);
  for (const FrameField& f : cell_fields)
    poly->GetCellData()->AddArray(full_array(f, n_cells, "triangle field size"));
  return poly;
}

// Writes and reports failure by the return value only: VTK's own error dump (object addresses,
// source lines) is silenced, fdem reports the failure as one message.
// `system_error` receives errno as the write left it (0 if it set none).
bool write_succeeded(vtkXMLWriter* writer, int& system_error) {
  const int warnings = vtkObject::GetGlobalWarningDisplay();
  vtkObject::GlobalWarningDisplayOff();
  errno = 0;
  const bool ok = writer->Write() == 1 && writer->GetErrorCode() == vtkErrorCode::NoError;
  system_error = errno;
  vtkObject::SetGlobalWarningDisplay(warnings);
  return ok;
}

// The reason of a failed VTK write: the system's when it set one, else VTK's error code.
std::string write_failure(vtkXMLWriter* writer, int system_error) {
  if (system_error != 0) return std::strerror(system_error);
  switch (writer->GetErrorCode()) {
    case vtkErrorCode::OutOfDiskSpaceError:
      return "out of disk space";
    case vtkErrorCode::CannotOpenFileError:
      return "cannot open the file";
    default:
      return "VTK error code " + std::to_string(writer->GetErrorCode());
  }
}

// One-rank frame: `data` to `path` through `<path>.tmp`.
template <class Writer>
void write_serial(const std::string& path, vtkDataObject* data) {
  const std::string tmp = path + ".tmp";
  vtkNew<Writer> writer;
  writer->SetFileName(tmp.c_str());
  writer->SetInputData(data);
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressionLevel(frame_compression_level);
  int system_error = 0;
  if (!write_succeeded(writer, system_error)) {
    const std::string reason = write_failure(writer, system_error);
    remove_partial(tmp);
    throw IoError("cannot write the frame " + path + ": " + reason);
  }
  std::error_code error;
  std::filesystem::rename(tmp, path, error);
  if (error) {
    remove_partial(tmp);
    throw IoError("cannot rename " + tmp + " to " + path + ": " + error.message());
  }
}

// VTK's parallel XML writer (vtkXMLPUnstructuredGridWriter, vtkXMLPPolyDataWriter) adapted to
// ranks that each write their own piece without a VTK MPI controller:
// - VTK skips a piece with no points and no cells; here it is written (same arrays, zero tuples),
//   so every piece the summary lists exists;
// - without a controller VTK lists in the summary only the pieces that this process wrote; here
//   the summary lists all NumberOfPieces (each rank writes its piece);
// - a piece is written under `<piece>.tmp` and renamed.
template <class ParallelWriter>
class EveryPieceWriter : public ParallelWriter {
 public:
  int SystemError = 0;  // errno of a failed piece write (its reason), 0 if none

  static EveryPieceWriter* New() {
    auto* writer = new EveryPieceWriter;
    writer->InitializeObjectBase();
    return writer;
  }

 protected:
  int WritePieceInternal() override {
    const int piece = this->GetCurrentPiece();
    if (!this->WritePiece(piece)) return 0;
    this->PieceWrittenFlags[piece] = 1;
    return 1;
  }

  void PrepareSummaryFile() override {
    std::fill_n(this->PieceWrittenFlags, this->NumberOfPieces, static_cast<unsigned char>(1));
  }

  // vtkXMLPDataWriter::WritePiece with the piece writer's settings, through a temporary name.
  int WritePiece(int index) override {
    vtkXMLWriter* piece = this->CreatePieceWriter(index);
    char* name = this->CreatePieceFileName(index, this->PathName);
    const std::string path = name;
    delete[] name;
    const std::string tmp = path + ".tmp";
    piece->SetFileName(tmp.c_str());
    piece->SetCompressor(this->GetCompressor());
    piece->SetDataMode(this->GetDataMode());
    piece->SetByteOrder(this->GetByteOrder());
    piece->SetEncodeAppendedData(this->GetEncodeAppendedData());
    piece->SetHeaderType(this->GetHeaderType());
    piece->SetBlockSize(this->GetBlockSize());
    errno = 0;
    int result = piece->Write();
    if (errno != 0) this->SystemError = errno;
    const unsigned long error = piece->GetErrorCode();
    piece->Delete();
    this->SetErrorCode(error);
    if (result != 1 || error != vtkErrorCode::NoError) {
      remove_partial(tmp);
      return 0;
    }
    std::error_code renamed;
    std::filesystem::rename(tmp, path, renamed);
    if (renamed) {
      remove_partial(tmp);
      this->SetErrorCode(vtkErrorCode::CannotOpenFileError);
      result = 0;
    }
    return result;
  }
};

// Piece `rank` of `ranks` of frame `stem`; rank 0 also writes the summary (through its .tmp).
template <class ParallelWriter>
void write_piece(const std::string& stem, const std::string& extension, vtkDataObject* data,
                 int rank, int ranks) {
  const std::string summary = frame_file_name(stem, extension, ranks);
  vtkSmartPointer<EveryPieceWriter<ParallelWriter>> writer =
      vtkSmartPointer<EveryPieceWriter<ParallelWriter>>::Take(
          EveryPieceWriter<ParallelWriter>::New());
  writer->SetController(nullptr);        // ranks are plain numbers here; no VTK communication
  writer->SetFileName(summary.c_str());  // sets the piece names: <stem>_<rank>.<extension>
  writer->SetInputData(data);
  writer->SetNumberOfPieces(ranks);
  writer->SetStartPiece(rank);
  writer->SetEndPiece(rank);
  writer->SetGhostLevel(0);
  writer->SetWriteSummaryFile(rank == 0);
  writer->SetWriteToOutputString(rank == 0);  // the summary goes to a string, then atomically out
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressionLevel(frame_compression_level);
  int system_error = 0;
  if (!write_succeeded(writer, system_error))
    throw IoError("cannot write the frame piece " + frame_piece_name(stem, extension, rank) + ": " +
                  write_failure(writer, writer->SystemError ? writer->SystemError : system_error));
  if (rank == 0) write_file_atomically(summary, writer->GetOutputString());
}

// Checks the rank numbers; true on one rank (a plain .vtu/.vtp, no pieces).
bool single_rank(int rank, int ranks) {
  FDEM_VERIFY(ranks >= 1 && rank >= 0 && rank < ranks, "frame rank");
  return ranks == 1;
}

}  // namespace

void write_tet_frame(const std::string& path, const Model& model,
                     const std::vector<std::string>& fields, const std::vector<FrameField>& extra) {
  write_serial<vtkXMLUnstructuredGridWriter>(path, owned_tet_grid(model, fields, extra));
}

void write_parallel_tet_frame(const std::string& stem, const Model& model,
                              const std::vector<std::string>& fields,
                              const std::vector<FrameField>& extra, int rank, int ranks) {
  if (single_rank(rank, ranks))
    return write_tet_frame(frame_file_name(stem, "vtu", 1), model, fields, extra);
  write_piece<vtkXMLPUnstructuredGridWriter>(stem, "vtu", owned_tet_grid(model, fields, extra),
                                             rank, ranks);
}

void write_point_frame(const std::string& path, const std::vector<double>& points,
                       const std::vector<FrameField>& point_fields) {
  write_serial<vtkXMLPolyDataWriter>(path, point_poly(points, point_fields));
}

void write_parallel_point_frame(const std::string& stem, const std::vector<double>& points,
                                const std::vector<FrameField>& point_fields, int rank, int ranks) {
  if (single_rank(rank, ranks))
    return write_point_frame(frame_file_name(stem, "vtp", 1), points, point_fields);
  write_piece<vtkXMLPPolyDataWriter>(stem, "vtp", point_poly(points, point_fields), rank, ranks);
}

void write_triangle_frame(const std::string& path, const std::vector<double>& points,
                          const std::vector<std::int64_t>& triangles,
                          const std::vector<FrameField>& cell_fields) {
  write_serial<vtkXMLPolyDataWriter>(path, triangle_poly(points, triangles, cell_fields));
}

void write_parallel_triangle_frame(const std::string& stem, const std::vector<double>& points,
                                   const std::vector<std::int64_t>& triangles,
                                   const std::vector<FrameField>& cell_fields, int rank,
                                   int ranks) {
  if (single_rank(rank, ranks))
    return write_triangle_frame(frame_file_name(stem, "vtp", 1), points, triangles, cell_fields);
  write_piece<vtkXMLPPolyDataWriter>(stem, "vtp", triangle_poly(points, triangles, cell_fields),
                                     rank, ranks);
}

}  // namespace fdem
