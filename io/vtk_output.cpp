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
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "core/error.hpp"
#include "core/tet_kernels.hpp"

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

vtkNew<vtkDoubleArray> make_array(const std::string& name, int components, vtkIdType tuples) {
  vtkNew<vtkDoubleArray> a;
  a->SetName(name.c_str());
  a->SetNumberOfComponents(components);
  a->SetNumberOfTuples(tuples);
  return a;
}

// Copies the tuples `kept` of a FrameField given for all `all_tuples` entries.
vtkNew<vtkDoubleArray> filtered_array(const FrameField& f, vtkIdType all_tuples,
                                      const std::vector<LocalIndex>& kept) {
  FDEM_VERIFY(static_cast<vtkIdType>(f.values.size()) == all_tuples * f.components,
              "frame field size");
  auto a = make_array(f.name, f.components, static_cast<vtkIdType>(kept.size()));
  for (std::size_t i = 0; i < kept.size(); ++i)
    for (int c = 0; c < f.components; ++c)
      a->SetComponent(static_cast<vtkIdType>(i), c,
                      f.values[static_cast<std::size_t>(kept[i]) * f.components + c]);
  return a;
}

vtkNew<vtkDoubleArray> full_array(const FrameField& f, vtkIdType tuples, const char* what) {
  FDEM_VERIFY(static_cast<vtkIdType>(f.values.size()) == tuples * f.components, what);
  auto a = make_array(f.name, f.components, tuples);
  for (vtkIdType i = 0; i < tuples * f.components; ++i) a->SetValue(i, f.values[i]);
  return a;
}

// The owned tets of `model` and the nodes they reference, renumbered in ascending local order
// (on one rank with every node in a tet, the identity).
vtkSmartPointer<vtkUnstructuredGrid> owned_tet_grid(const Model& model,
                                                    const std::vector<std::string>& fields,
                                                    const std::vector<FrameField>& extra) {
  const NodeArrays& nodes = model.nodes;
  const TetArrays& tets = model.tets;
  const auto wants = [&](const char* f) {
    return std::find(fields.begin(), fields.end(), f) != fields.end();
  };

  std::vector<LocalIndex> cells;  // local tets written, ascending (so ascending gid)
  std::vector<LocalIndex> renumbered(nodes.size(), -1);
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    if (!tets.is_owned(t)) continue;
    cells.push_back(t);
    for (int c = 0; c < 4; ++c) renumbered[tets.nodes[4 * t + c]] = 0;
  }
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

  vtkNew<vtkTypeInt64Array> node_gid;
  node_gid->SetName("gid");
  node_gid->SetNumberOfTuples(n_points);
  for (vtkIdType p = 0; p < n_points; ++p) node_gid->SetValue(p, nodes.gid[points[p]]);
  grid->GetPointData()->AddArray(node_gid);
  if (wants("displacement")) {
    auto u = make_array("displacement", 3, n_points);
    for (vtkIdType p = 0; p < n_points; ++p)
      for (int k = 0; k < 3; ++k)
        u->SetComponent(p, k, nodes.x[3 * points[p] + k] - nodes.x0[3 * points[p] + k]);
    grid->GetPointData()->AddArray(u);
  }
  if (wants("velocity")) {
    auto v = make_array("velocity", 3, n_points);
    for (vtkIdType p = 0; p < n_points; ++p)
      for (int k = 0; k < 3; ++k) v->SetComponent(p, k, nodes.v[3 * points[p] + k]);
    grid->GetPointData()->AddArray(v);
  }

  vtkNew<vtkTypeInt64Array> tet_gid;
  tet_gid->SetName("gid");
  tet_gid->SetNumberOfTuples(n_cells);
  vtkNew<vtkIntArray> piece, body, material;
  piece->SetName("piece");
  body->SetName("body");
  material->SetName("material");
  for (auto* a : {piece.GetPointer(), body.GetPointer(), material.GetPointer()})
    a->SetNumberOfTuples(n_cells);
  for (vtkIdType c = 0; c < n_cells; ++c) {
    const LocalIndex t = cells[c];
    tet_gid->SetValue(c, tets.gid[t]);
    piece->SetValue(c, tets.piece[t]);
    body->SetValue(c, model.pieces[tets.piece[t]].body);
    material->SetValue(c, tets.material[t]);
  }
  grid->GetCellData()->AddArray(tet_gid);
  grid->GetCellData()->AddArray(piece);
  grid->GetCellData()->AddArray(body);
  grid->GetCellData()->AddArray(material);

  if (wants("stress")) {
    auto sigma = make_array("stress", 9, n_cells);
    auto mises = make_array("von_mises", 1, n_cells);
    for (vtkIdType c = 0; c < n_cells; ++c) {
      const LocalIndex t = cells[c];
      Vec3 x[4];
      for (int k = 0; k < 4; ++k) x[k] = vec3_at(nodes.x.data(), tets.nodes[4 * t + k]);
      const Mat3 F = edge_matrix(x) * Eigen::Map<const Mat3>(tets.dm_inv.data() + 9 * t);
      const MaterialProperties& mat = model.materials[tets.material[t]];
      Mat3 cauchy = Mat3::Zero();
      const double J = F.determinant();
      if (J > 0.0) {
        const Mat3 P = mat.model == ElasticModel::neo_hookean
                           ? NeoHookean{mat.lame}.first_piola(F)
                           : StVenantKirchhoff{mat.lame}.first_piola(F);
        cauchy = P * F.transpose() / J;
      }
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) sigma->SetComponent(c, 3 * i + j, cauchy(i, j));
      const Mat3 dev = cauchy - cauchy.trace() / 3.0 * Mat3::Identity();
      mises->SetValue(c, std::sqrt(1.5 * dev.squaredNorm()));
    }
    grid->GetCellData()->AddArray(sigma);
    grid->GetCellData()->AddArray(mises);
  }
  for (const FrameField& f : extra) {
    if (f.per_cell)
      grid->GetCellData()->AddArray(filtered_array(f, tets.size(), cells));
    else
      grid->GetPointData()->AddArray(filtered_array(f, nodes.size(), points));
  }
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
