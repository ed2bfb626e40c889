#include "io/vtk_output.hpp"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "core/error.hpp"
#include "core/tet_kernels.hpp"

namespace fdem {

void write_file_atomically(const std::string& path, const std::string& content) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    out << content;
    if (!out) throw std::runtime_error("cannot write " + tmp + " (disk full or no permission?)");
  }
  std::filesystem::rename(tmp, path);
}

SeriesWriter::SeriesWriter(std::string directory, std::string series)
    : directory_(std::move(directory)), series_(std::move(series)) {
  std::filesystem::create_directories(std::filesystem::path(directory_) / series_);
}

std::string SeriesWriter::next_frame_path() {
  std::ostringstream name;
  name << series_ << "/" << series_ << "_" << std::setw(6) << std::setfill('0') << entries_.size();
  return name.str();
}

void SeriesWriter::add_frame(double time, const std::string& relative_path) {
  entries_.emplace_back(time, relative_path);
  write_pvd();
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

}  // namespace

void write_tet_frame(const std::string& path, const Model& model,
                     const std::vector<std::string>& fields, const std::vector<FrameField>& extra) {
  const NodeArrays& nodes = model.nodes;
  const TetArrays& tets = model.tets;
  const auto wants = [&](const char* f) {
    return std::find(fields.begin(), fields.end(), f) != fields.end();
  };
  const vtkIdType n_points = nodes.size(), n_cells = tets.size();

  vtkNew<vtkUnstructuredGrid> grid;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n_points);
  for (vtkIdType i = 0; i < n_points; ++i) points->SetPoint(i, &nodes.x[3 * i]);
  grid->SetPoints(points);
  grid->Allocate(n_cells);
  for (vtkIdType t = 0; t < n_cells; ++t) {
    const vtkIdType ids[4] = {tets.nodes[4 * t], tets.nodes[4 * t + 1], tets.nodes[4 * t + 2],
                              tets.nodes[4 * t + 3]};
    grid->InsertNextCell(VTK_TETRA, 4, ids);
  }

  vtkNew<vtkIntArray> gid_points;
  gid_points->SetName("node_id");
  gid_points->SetNumberOfTuples(n_points);
  for (vtkIdType i = 0; i < n_points; ++i) gid_points->SetValue(i, static_cast<int>(nodes.gid[i]));
  grid->GetPointData()->AddArray(gid_points);
  if (wants("displacement")) {
    auto u = make_array("displacement", 3, n_points);
    for (vtkIdType i = 0; i < 3 * n_points; ++i) u->SetValue(i, nodes.x[i] - nodes.x0[i]);
    grid->GetPointData()->AddArray(u);
  }
  if (wants("velocity")) {
    auto v = make_array("velocity", 3, n_points);
    for (vtkIdType i = 0; i < 3 * n_points; ++i) v->SetValue(i, nodes.v[i]);
    grid->GetPointData()->AddArray(v);
  }

  vtkNew<vtkIntArray> piece, body, material;
  piece->SetName("piece");
  body->SetName("body");
  material->SetName("material");
  for (auto* a : {piece.GetPointer(), body.GetPointer(), material.GetPointer()})
    a->SetNumberOfTuples(n_cells);
  for (vtkIdType t = 0; t < n_cells; ++t) {
    piece->SetValue(t, tets.piece[t]);
    body->SetValue(t, model.pieces[tets.piece[t]].body);
    material->SetValue(t, tets.material[t]);
  }
  grid->GetCellData()->AddArray(piece);
  grid->GetCellData()->AddArray(body);
  grid->GetCellData()->AddArray(material);

  if (wants("stress")) {
    auto sigma = make_array("stress", 9, n_cells);
    auto mises = make_array("von_mises", 1, n_cells);
    for (vtkIdType t = 0; t < n_cells; ++t) {
      Vec3 x[4];
      for (int c = 0; c < 4; ++c) x[c] = vec3_at(nodes.x.data(), tets.nodes[4 * t + c]);
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
        for (int j = 0; j < 3; ++j) sigma->SetComponent(t, 3 * i + j, cauchy(i, j));
      const Mat3 dev = cauchy - cauchy.trace() / 3.0 * Mat3::Identity();
      mises->SetValue(t, std::sqrt(1.5 * dev.squaredNorm()));
    }
    grid->GetCellData()->AddArray(sigma);
    grid->GetCellData()->AddArray(mises);
  }
  for (const FrameField& f : extra) {
    const vtkIdType tuples = f.per_cell ? n_cells : n_points;
    FDEM_VERIFY(static_cast<vtkIdType>(f.values.size()) == tuples * f.components,
                "frame field size");
    auto a = make_array(f.name, f.components, tuples);
    for (vtkIdType i = 0; i < tuples * f.components; ++i) a->SetValue(i, f.values[i]);
    (f.per_cell ? static_cast<vtkDataSetAttributes*>(grid->GetCellData())
                : static_cast<vtkDataSetAttributes*>(grid->GetPointData()))
        ->AddArray(a);
  }

  const std::string tmp = path + ".tmp";
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->SetFileName(tmp.c_str());
  writer->SetInputData(grid);
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  if (writer->Write() != 1) throw std::runtime_error("VTK could not write " + tmp);
  std::filesystem::rename(tmp, path);
}

void write_point_frame(const std::string& path, const std::vector<double>& points,
                       const std::vector<FrameField>& point_fields) {
  const vtkIdType n = static_cast<vtkIdType>(points.size() / 3);
  vtkNew<vtkPolyData> poly;
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
  for (const FrameField& f : point_fields) {
    FDEM_VERIFY(static_cast<vtkIdType>(f.values.size()) == n * f.components, "point field size");
    auto a = make_array(f.name, f.components, n);
    for (vtkIdType i = 0; i < n * f.components; ++i) a->SetValue(i, f.values[i]);
    poly->GetPointData()->AddArray(a);
  }
  const std::string tmp = path + ".tmp";
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetFileName(tmp.c_str());
  writer->SetInputData(poly);
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  if (writer->Write() != 1) throw std::runtime_error("VTK could not write " + tmp);
  std::filesystem::rename(tmp, path);
}

void write_triangle_frame(const std::string& path, const std::vector<double>& points,
                          const std::vector<std::int64_t>& triangles,
                          const std::vector<FrameField>& cell_fields) {
  const vtkIdType n_points = static_cast<vtkIdType>(points.size() / 3);
  const vtkIdType n_cells = static_cast<vtkIdType>(triangles.size() / 3);
  vtkNew<vtkPolyData> poly;
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
  for (const FrameField& f : cell_fields) {
    FDEM_VERIFY(static_cast<vtkIdType>(f.values.size()) == n_cells * f.components,
                "triangle field size");
    auto a = make_array(f.name, f.components, n_cells);
    for (vtkIdType i = 0; i < n_cells * f.components; ++i) a->SetValue(i, f.values[i]);
    poly->GetCellData()->AddArray(a);
  }
  const std::string tmp = path + ".tmp";
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetFileName(tmp.c_str());
  writer->SetInputData(poly);
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  if (writer->Write() != 1) throw std::runtime_error("VTK could not write " + tmp);
  std::filesystem::rename(tmp, path);
}

}  // namespace fdem
