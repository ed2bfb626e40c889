#include "io/vtk_output.hpp"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkXMLPPolyDataWriter.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "core/error.hpp"
#include "io/vtu_stream.hpp"

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

// A frame column as a streamed .vtu array: f64 → Float64, i64 → Int64, i32 → Int32.
VtuArray vtu_array(const FrameColumn& c) {
  const char* type = c.type == FrameValue::f64   ? "Float64"
                     : c.type == FrameValue::i64 ? "Int64"
                                                 : "Int32";
  VtuArray a{c.name, type, c.components, c.rows, {}};
  const std::size_t n = static_cast<std::size_t>(c.components);
  a.fill = [&c, n](std::size_t first, std::size_t count, unsigned char* out) {
    if (c.type == FrameValue::f64) {
      std::vector<double> values(count * n);
      c.fill_real(first, count, values.data());
      std::memcpy(out, values.data(), values.size() * sizeof(double));
      return;
    }
    std::vector<std::int64_t> values(count * n);
    c.fill_integer(first, count, values.data());
    if (c.type == FrameValue::i64) {
      std::memcpy(out, values.data(), values.size() * sizeof(std::int64_t));
      return;
    }
    for (std::size_t i = 0; i < values.size(); ++i) {
      const auto value = static_cast<std::int32_t>(values[i]);
      std::memcpy(out + 4 * i, &value, 4);
    }
  };
  return a;
}

// The owned tets of `model` and the nodes they reference, renumbered in ascending local order,
// as a streamed .vtu grid.  On one rank, where every tet is owned and every node in a tet, that
// is the identity and no index list is built (they were ~40 B per tet at a frame, the run's peak
// of a large jointed body).  The grid's arrays read the model and this object, which is neither
// copied nor moved.
class OwnedTetGrid {
 public:
  OwnedTetGrid(const Model& model, const std::vector<std::string>& fields,
               const std::vector<FrameField>& extra) {
    const NodeArrays& nodes = model.nodes;
    const TetArrays& tets = model.tets;
    const auto n_nodes = static_cast<std::size_t>(nodes.size());
    std::size_t owned = 0;
    std::vector<bool> used(n_nodes, false);
    for (LocalIndex t = 0; t < tets.size(); ++t)
      if (tets.is_owned(t)) {
        ++owned;
        for (int c = 0; c < 4; ++c) used[static_cast<std::size_t>(tets.nodes[4 * t + c])] = true;
      }
    const auto n_used = static_cast<std::size_t>(std::count(used.begin(), used.end(), true));
    identity_ = owned == static_cast<std::size_t>(tets.size()) && n_used == n_nodes;
    if (!identity_) {
      cells_ = owned_tets(tets);
      renumbered_.assign(n_nodes, -1);
      points_.reserve(n_used);
      for (std::size_t i = 0; i < n_nodes; ++i)
        if (used[i]) {
          renumbered_[i] = static_cast<LocalIndex>(points_.size());
          points_.push_back(static_cast<LocalIndex>(i));
        }
    }
    const LocalSelection cells = identity_ ? LocalSelection::first(owned) : cells_;
    const LocalSelection points = identity_ ? LocalSelection::first(n_nodes) : points_;
    columns_ = tet_frame_columns(model, cells, points, fields, extra);
    grid_.points = points.size();
    grid_.cells = cells.size();
    for (const FrameColumn& c : columns_)
      (c.per_cell ? grid_.cell_data : grid_.point_data).push_back(vtu_array(c));
    grid_.positions = {"Points", "Float64", 3, points.size(),
                       [&nodes, points](std::size_t first, std::size_t count, unsigned char* out) {
                         for (std::size_t p = 0; p < count; ++p)
                           std::memcpy(out + 24 * p, &nodes.x[3 * points[first + p]], 24);
                       }};
    grid_.tet_corners = {
        "connectivity", "Int64", 4, cells.size(),
        [this, &tets, cells](std::size_t first, std::size_t count, unsigned char* out) {
          for (std::size_t c = 0; c < count; ++c)
            for (int k = 0; k < 4; ++k) {
              const LocalIndex n = tets.nodes[4 * cells[first + c] + k];
              const auto point = static_cast<std::int64_t>(identity_ ? n : renumbered_[n]);
              std::memcpy(out + 32 * c + 8 * k, &point, 8);
            }
        }};
  }
  OwnedTetGrid(const OwnedTetGrid&) = delete;
  OwnedTetGrid& operator=(const OwnedTetGrid&) = delete;
  const VtuGrid& grid() const { return grid_; }

 private:
  bool identity_ = false;  // every local tet and node written, in local order
  std::vector<LocalIndex> cells_, renumbered_, points_;  // points: local nodes written, ascending
  std::vector<FrameColumn> columns_;
  VtuGrid grid_;
};

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

// `tmp` renamed to `path` (removed if that fails).
void rename_into_place(const std::string& tmp, const std::string& path) {
  std::error_code error;
  std::filesystem::rename(tmp, path, error);
  if (error) {
    remove_partial(tmp);
    throw IoError("cannot rename " + tmp + " to " + path + ": " + error.message());
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
  rename_into_place(tmp, path);
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
  const OwnedTetGrid owned(model, fields, extra);
  const std::string tmp = path + ".tmp";
  write_vtu(tmp, owned.grid(), frame_compression_level, "cannot write the frame " + path);
  rename_into_place(tmp, path);
}

void write_parallel_tet_frame(const std::string& stem, const Model& model,
                              const std::vector<std::string>& fields,
                              const std::vector<FrameField>& extra, int rank, int ranks) {
  if (single_rank(rank, ranks))
    return write_tet_frame(frame_file_name(stem, "vtu", 1), model, fields, extra);
  const OwnedTetGrid owned(model, fields, extra);
  const std::string piece = frame_piece_name(stem, "vtu", rank);
  write_vtu(piece + ".tmp", owned.grid(), frame_compression_level,
            "cannot write the frame piece " + piece);
  rename_into_place(piece + ".tmp", piece);
  if (rank != 0) return;
  std::vector<std::string> pieces;
  for (int r = 0; r < ranks; ++r)
    pieces.push_back(std::filesystem::path(frame_piece_name(stem, "vtu", r)).filename().string());
  write_file_atomically(frame_file_name(stem, "vtu", ranks), pvtu_summary(owned.grid(), pieces));
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
