// ParaView output on several ranks, simulated in one process: the parallel writers are called once
// per rank index on a hand-made model whose tets are split between ranks by their `owned` flags.
// The summaries (.pvtu/.pvtp) are read back with VTK's parallel readers and compared, tet by tet
// (matched by gid), with the model and with a one-rank frame of the whole model.
#include <unistd.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPPolyDataReader.h>
#include <vtkXMLPUnstructuredGridReader.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/tet_kernels.hpp"
#include "io/vtk_output.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using fdem::FrameField;
using fdem::GlobalId;
using fdem::LocalIndex;
using fdem::Model;

namespace {

class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "fdem_vtk_XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot create a temp directory");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Files under `dir` (recursively) whose name ends in ".tmp": a finished write leaves none.
int temporary_files(const fs::path& dir) {
  int n = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.path().extension() == ".tmp") ++n;
  return n;
}

// The `file` attributes of the DataSet elements of a .pvd, in order.
std::vector<std::string> pvd_files(const std::string& path) {
  std::vector<std::string> files;
  const std::string text = read_text(path);
  const std::regex dataset(R"re(<DataSet\s[^>]*\sfile="([^"]+)")re");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), dataset);
       it != std::sregex_iterator(); ++it)
    files.push_back((*it)[1]);
  return files;
}

// Two unit hexahedra side by side along x (3×2×2 = 12 nodes), each cut into the 6 Kuhn tets around
// its main diagonal: 12 tets.  Hexahedron h is piece h of body h; the tets alternate between two
// materials.  Gids are not local indices (tet gid 2^40 + 10 + 3t, node gid 2^32 + 500 + 7i) so that
// a writer that mixes them up, or narrows them to 32 bits, fails.  The nodes are moved by a
// non-affine map (non-uniform stress) and get distinct velocities.
Model two_block_model() {
  Model m;
  const int nx = 3, ny = 2, nz = 2;
  const auto node = [&](int i, int j, int k) {
    return static_cast<LocalIndex>(i + nx * (j + ny * k));
  };
  m.nodes.resize(nx * ny * nz);
  m.nodes.n_owned = m.nodes.size();
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const LocalIndex n = node(i, j, k);
        const double X[3] = {1.0 * i, 1.0 * j, 1.0 * k};
        const double dx[3] = {1e-3 * X[0] + 2e-3 * X[1] * X[1], -5e-4 * X[1] + 1e-3 * X[2] * X[0],
                              3e-4 * X[0] * X[1] + 2e-4 * X[2]};
        m.nodes.gid[n] = (GlobalId{1} << 32) + 500 + 7 * n;
        m.nodes.add_reference(n, X);
        for (int c = 0; c < 3; ++c) {
          m.nodes.x[3 * n + c] = X[c] + dx[c];
          m.nodes.v[3 * n + c] = 0.1 * (n + 1) * (c + 1) * (c == 1 ? -1.0 : 1.0);
        }
      }
  const int permutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  m.tets.resize(12);
  for (int h = 0; h < 2; ++h)
    for (int p = 0; p < 6; ++p) {
      const LocalIndex t = 6 * h + p;
      int corner[3] = {h, 0, 0};
      m.tets.nodes[4 * t] = node(corner[0], corner[1], corner[2]);
      for (int s = 0; s < 3; ++s) {
        ++corner[permutations[p][s]];
        m.tets.nodes[4 * t + s + 1] = node(corner[0], corner[1], corner[2]);
      }
      fdem::Vec3 X[4];
      for (int c = 0; c < 4; ++c) X[c] = m.nodes.x0(m.tets.nodes[4 * t + c]);
      const fdem::Mat3 dm_inv = fdem::edge_matrix(X).inverse();
      std::copy(dm_inv.data(), dm_inv.data() + 9, m.tets.dm_inv.begin() + 9 * t);
      m.tets.volume0[t] = 1.0 / 6.0;
      m.tets.gid[t] = (GlobalId{1} << 40) + 10 + 3 * t;
      m.tets.piece[t] = h;
      m.tets.material[t] = t % 2;
    }
  for (int mat = 0; mat < 2; ++mat) {
    fdem::MaterialProperties props;
    props.name = mat == 0 ? "soft" : "stiff";
    props.density = 2000.0;
    props.model =
        mat == 0 ? fdem::ElasticModel::neo_hookean : fdem::ElasticModel::st_venant_kirchhoff;
    props.young = mat == 0 ? 1e8 : 2e10;
    props.poisson = 0.25;
    props.lame = fdem::LameParameters::from_young_poisson(props.young, props.poisson);
    m.materials.push_back(props);
  }
  m.pieces.add_body(1);  // one piece in each of the two bodies
  m.pieces.add_body(1);
  m.body_names = {"left", "right"};
  m.body_fixed = {false, false};
  return m;
}

const std::vector<std::string> kFields = {"displacement", "velocity", "stress"};

// Per local tet (1 and 3 components) and per local node: values that identify their entry.
std::vector<FrameField> extra_fields(const Model& m) {
  FrameField damage{"damage", 1, true, {}}, direction{"direction", 3, true, {}};
  FrameField temperature{"temperature", 1, false, {}};
  for (LocalIndex t = 0; t < m.tets.size(); ++t) {
    damage.values.push_back(0.01 * t);
    for (int c = 0; c < 3; ++c) direction.values.push_back(100.0 * t + c);
  }
  for (LocalIndex n = 0; n < m.nodes.size(); ++n) temperature.values.push_back(273.0 + 1.5 * n);
  return {damage, direction, temperature};
}

std::vector<double> tuple(vtkDataArray* a, vtkIdType i) {
  std::vector<double> out;
  for (int c = 0; c < a->GetNumberOfComponents(); ++c) out.push_back(a->GetComponent(i, c));
  return out;
}

// Cell-data tuples of a grid, keyed by the cell's gid.
using CellValues = std::map<GlobalId, std::map<std::string, std::vector<double>>>;
CellValues cell_values(vtkDataSet* grid) {
  CellValues values;
  vtkDataArray* gid = grid->GetCellData()->GetArray("gid");
  REQUIRE(gid);
  for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c) {
    auto& row = values[static_cast<GlobalId>(gid->GetComponent(c, 0))];
    for (int a = 0; a < grid->GetCellData()->GetNumberOfArrays(); ++a) {
      vtkDataArray* array = grid->GetCellData()->GetArray(a);
      row[array->GetName()] = tuple(array, c);
    }
  }
  return values;
}

// Names and component counts of the point and cell arrays.
std::map<std::string, int> array_layout(vtkDataSet* data) {
  std::map<std::string, int> layout;
  for (int a = 0; a < data->GetPointData()->GetNumberOfArrays(); ++a)
    layout[std::string("point ") + data->GetPointData()->GetArrayName(a)] =
        data->GetPointData()->GetArray(a)->GetNumberOfComponents();
  for (int a = 0; a < data->GetCellData()->GetNumberOfArrays(); ++a)
    layout[std::string("cell ") + data->GetCellData()->GetArrayName(a)] =
        data->GetCellData()->GetArray(a)->GetNumberOfComponents();
  return layout;
}

vtkSmartPointer<vtkUnstructuredGrid> read_vtu(const std::string& path) {
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  return reader->GetOutput();
}

vtkSmartPointer<vtkUnstructuredGrid> read_pvtu(const std::string& path) {
  vtkNew<vtkXMLPUnstructuredGridReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  return reader->GetOutput();
}

// Every tet of `m` once in `grid` (by gid), with the model's node coordinates, node gids,
// displacements, velocities and per-node extra field at its corners, and the cell values of
// `reference` (a one-rank frame of the whole model).
void check_frame_against_model(vtkUnstructuredGrid* grid, const Model& m,
                               const CellValues& reference) {
  REQUIRE(grid->GetNumberOfCells() == m.tets.size());
  std::map<GlobalId, LocalIndex> tet_of_gid;
  for (LocalIndex t = 0; t < m.tets.size(); ++t) tet_of_gid[m.tets.gid[t]] = t;
  vtkDataArray* cell_gid = grid->GetCellData()->GetArray("gid");
  vtkDataArray* node_gid = grid->GetPointData()->GetArray("gid");
  vtkDataArray* u = grid->GetPointData()->GetArray("displacement");
  vtkDataArray* v = grid->GetPointData()->GetArray("velocity");
  vtkDataArray* temperature = grid->GetPointData()->GetArray("temperature");
  REQUIRE(cell_gid);
  REQUIRE(node_gid);
  REQUIRE(u);
  REQUIRE(v);
  REQUIRE(temperature);
  std::multiset<GlobalId> seen;
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c) {
    const auto gid = static_cast<GlobalId>(cell_gid->GetComponent(c, 0));
    seen.insert(gid);
    REQUIRE(tet_of_gid.count(gid) == 1);
    const LocalIndex t = tet_of_gid[gid];
    CHECK(grid->GetCellType(c) == VTK_TETRA);
    grid->GetCellPoints(c, ids);
    REQUIRE(ids->GetNumberOfIds() == 4);
    for (int corner = 0; corner < 4; ++corner) {
      const vtkIdType p = ids->GetId(corner);
      const LocalIndex n = m.tets.nodes[4 * t + corner];
      double x[3];
      grid->GetPoint(p, x);
      for (int k = 0; k < 3; ++k) {
        CHECK(x[k] == m.nodes.x[3 * n + k]);
        CHECK(u->GetComponent(p, k) == m.nodes.x[3 * n + k] - m.nodes.x0(n)[k]);
        CHECK(v->GetComponent(p, k) == m.nodes.v[3 * n + k]);
      }
      CHECK(node_gid->GetComponent(p, 0) == m.nodes.gid[n]);
      CHECK(temperature->GetComponent(p, 0) == 273.0 + 1.5 * n);
    }
  }
  for (LocalIndex t = 0; t < m.tets.size(); ++t) CHECK(seen.count(m.tets.gid[t]) == 1);
  CHECK(cell_values(grid) == reference);
}

// Writes frame `stem` as `owner.size()` ranks would: rank r owns the tets with owner[t] == r.
void write_as_ranks(const std::string& stem, Model m, const std::vector<int>& owner, int ranks) {
  for (int rank = 0; rank < ranks; ++rank) {
    m.tets.owned.assign(m.tets.size(), 0);
    for (LocalIndex t = 0; t < m.tets.size(); ++t) m.tets.owned[t] = owner[t] == rank;
    fdem::write_parallel_tet_frame(stem, m, kFields, extra_fields(m), rank, ranks);
  }
}

}  // namespace

TEST_CASE("one-rank tet frame: every tet and node, gids, fields per local entry", "[io][vtk]") {
  TempDir dir;
  const Model m = two_block_model();
  fdem::write_tet_frame(dir / "whole.vtu", m, kFields, extra_fields(m));
  auto grid = read_vtu(dir / "whole.vtu");
  REQUIRE(grid->GetNumberOfPoints() == 12);
  // All nodes are referenced, so they keep their local order.
  vtkDataArray* node_gid = grid->GetPointData()->GetArray("gid");
  REQUIRE(node_gid);
  for (LocalIndex n = 0; n < 12; ++n) CHECK(node_gid->GetComponent(n, 0) == m.nodes.gid[n]);
  const CellValues values = cell_values(grid);
  REQUIRE(values.size() == 12);
  for (LocalIndex t = 0; t < 12; ++t) {
    const auto& row = values.at(m.tets.gid[t]);
    CHECK(row.at("piece") == std::vector<double>{double(m.tets.piece[t])});
    CHECK(row.at("body") == std::vector<double>{double(t / 6)});
    CHECK(row.at("material") == std::vector<double>{double(t % 2)});
    CHECK(row.at("damage") == std::vector<double>{0.01 * t});
    CHECK(row.at("direction") == std::vector<double>{100.0 * t, 100.0 * t + 1, 100.0 * t + 2});
    CHECK(row.at("stress").size() == 9);
    CHECK(row.at("von_mises")[0] > 0.0);
  }
  check_frame_against_model(grid, m, values);
  CHECK(temporary_files(dir.path()) == 0);

  // Through the parallel entry point, one rank writes the plain .vtu and nothing else.
  fdem::write_parallel_tet_frame(dir / "single", m, kFields, extra_fields(m), 0, 1);
  CHECK(fs::exists(dir / "single.vtu"));
  CHECK_FALSE(fs::exists(dir / "single.pvtu"));
  CHECK_FALSE(fs::exists(dir / "single_0.vtu"));
  CHECK(cell_values(read_vtu(dir / "single.vtu")) == values);
}

TEST_CASE("a uniform stretch gives the analytic Cauchy stress in every piece", "[io][vtk]") {
  // St Venant–Kirchhoff under F = diag(1 + e, 1, 1): E = diag(a, 0, 0) with a = ((1 + e)² − 1)/2,
  // S = diag((λ + 2μ) a, λ a, λ a), σ = F S Fᵀ / J = diag((1 + e)(λ + 2μ) a, λ a/(1 + e), λ a/(1 +
  // e)).
  TempDir dir;
  Model m = two_block_model();
  const double e = 2e-3;
  for (LocalIndex n = 0; n < m.nodes.size(); ++n) {
    m.nodes.x[3 * n] = (1.0 + e) * m.nodes.x0(n)[0];
    m.nodes.x[3 * n + 1] = m.nodes.x0(n)[1];
    m.nodes.x[3 * n + 2] = m.nodes.x0(n)[2];
  }
  std::fill(m.tets.material.begin(), m.tets.material.end(), 1);
  const fdem::LameParameters lame = m.materials[1].lame;
  const double a = 0.5 * ((1 + e) * (1 + e) - 1);
  const double sxx = (1 + e) * (lame.lambda + 2 * lame.mu) * a, syy = lame.lambda * a / (1 + e);
  const std::vector<int> owner = {0, 0, 1, 0, 1, 1, 0, 1, 1, 0, 0, 1};
  write_as_ranks(dir / "stretch", m, owner, 2);
  auto grid = read_pvtu(dir / "stretch.pvtu");
  REQUIRE(grid->GetNumberOfCells() == 12);
  vtkDataArray* sigma = grid->GetCellData()->GetArray("stress");
  vtkDataArray* mises = grid->GetCellData()->GetArray("von_mises");
  REQUIRE(sigma);
  REQUIRE(mises);
  for (vtkIdType c = 0; c < 12; ++c) {
    const double expected[9] = {sxx, 0, 0, 0, syy, 0, 0, 0, syy};
    for (int k = 0; k < 9; ++k)
      CHECK(sigma->GetComponent(c, k) == Approx(expected[k]).margin(1e-9 * sxx));
    CHECK(mises->GetComponent(c, 0) == Approx(sxx - syy).epsilon(1e-9));  // uniaxial: |σxx − σyy|
  }
}

TEST_CASE("tet frame on 2 and 3 ranks: pieces, summary, every tet once", "[io][vtk]") {
  TempDir dir;
  const Model m = two_block_model();
  fdem::write_tet_frame(dir / "whole.vtu", m, kFields, extra_fields(m));
  auto whole = read_vtu(dir / "whole.vtu");
  const CellValues reference = cell_values(whole);

  struct Split {
    std::string name;
    int ranks;
    std::vector<int> owner;  // rank owning local tet t
  };
  const std::vector<Split> splits = {
      {"two", 2, {0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1}},
      {"three_middle_empty", 3, {0, 2, 0, 2, 0, 2, 0, 2, 0, 2, 0, 2}},
      {"three_first_empty", 3, {1, 1, 1, 1, 1, 1, 2, 2, 2, 2, 2, 2}},
  };
  for (const Split& split : splits) {
    SECTION(split.name) {
      const std::string stem = dir / split.name;
      write_as_ranks(stem, m, split.owner, split.ranks);
      CHECK(temporary_files(dir.path()) == 0);

      // The summary lists every piece under VTK's piece name, relative to the summary.
      const std::string summary = read_text(stem + ".pvtu");
      for (int r = 0; r < split.ranks; ++r)
        CHECK_THAT(summary,
                   Contains("Source=\"" + split.name + "_" + std::to_string(r) + ".vtu\""));
      CHECK_FALSE(fs::exists(stem + "_" + std::to_string(split.ranks) + ".vtu"));

      // Each piece: the owned tets and only the nodes they reference; an empty piece has no cells
      // and no points, and the same arrays as the whole frame.
      for (int r = 0; r < split.ranks; ++r) {
        INFO("piece " << r);
        const std::string piece = fdem::frame_piece_name(stem, "vtu", r);
        CHECK(piece == stem + "_" + std::to_string(r) + ".vtu");
        REQUIRE(fs::exists(piece));
        auto grid = read_vtu(piece);
        std::set<LocalIndex> nodes;
        vtkIdType owned = 0;
        for (LocalIndex t = 0; t < m.tets.size(); ++t)
          if (split.owner[t] == r) {
            ++owned;
            for (int c = 0; c < 4; ++c) nodes.insert(m.tets.nodes[4 * t + c]);
          }
        CHECK(grid->GetNumberOfCells() == owned);
        CHECK(grid->GetNumberOfPoints() == static_cast<vtkIdType>(nodes.size()));
        CHECK(array_layout(grid) == array_layout(whole));
      }

      auto grid = read_pvtu(stem + ".pvtu");
      CHECK(array_layout(grid) == array_layout(whole));
      check_frame_against_model(grid, m, reference);
    }
  }
}

TEST_CASE("a rank model with ghost nodes writes its owned tets with global ids", "[io][vtk]") {
  // Rank 1 of 2 holds tets 5..11 of the whole model: tet 5 is a ghost (owned by rank 0), and its
  // local nodes are in another order than the whole model's, with owned nodes first.
  TempDir dir;
  const Model whole = two_block_model();
  Model local = whole;
  const std::vector<LocalIndex> kept_tets = {5, 6, 7, 8, 9, 10, 11};
  std::vector<LocalIndex> local_node(whole.nodes.size(), -1), whole_node;
  for (int pass = 0; pass < 2; ++pass)  // nodes of the owned tets, then the rest (ghosts)
    for (const LocalIndex t : kept_tets)
      for (int c = 0; c < 4; ++c) {
        const LocalIndex n = whole.tets.nodes[4 * t + c];
        if ((pass == 0) == (t != 5) && local_node[n] < 0) {
          local_node[n] = static_cast<LocalIndex>(whole_node.size());
          whole_node.push_back(n);
        }
      }
  local.nodes.resize(static_cast<LocalIndex>(whole_node.size()));
  local.nodes.n_owned = 8;
  for (std::size_t i = 0; i < whole_node.size(); ++i) {
    const LocalIndex n = whole_node[i];
    local.nodes.gid[i] = whole.nodes.gid[n];
    local.nodes.add_reference(static_cast<LocalIndex>(i), whole.nodes.x0(n).data());
    for (int k = 0; k < 3; ++k) {
      local.nodes.x[3 * i + k] = whole.nodes.x[3 * n + k];
      local.nodes.v[3 * i + k] = whole.nodes.v[3 * n + k];
    }
  }
  local.tets.resize(static_cast<LocalIndex>(kept_tets.size()));
  local.tets.owned.assign(kept_tets.size(), 1);
  local.tets.owned[0] = 0;
  for (std::size_t i = 0; i < kept_tets.size(); ++i) {
    const LocalIndex t = kept_tets[i];
    local.tets.gid[i] = whole.tets.gid[t];
    for (int c = 0; c < 4; ++c)
      local.tets.nodes[4 * i + c] = local_node[whole.tets.nodes[4 * t + c]];
    std::copy_n(whole.tets.dm_inv.begin() + 9 * t, 9, local.tets.dm_inv.begin() + 9 * i);
    local.tets.material[i] = whole.tets.material[t];
    local.tets.piece[i] = whole.tets.piece[t];
  }
  fdem::write_tet_frame(dir / "whole.vtu", whole, kFields, {});
  const CellValues all = cell_values(read_vtu(dir / "whole.vtu"));
  fdem::write_tet_frame(dir / "local.vtu", local, kFields, {});
  auto grid = read_vtu(dir / "local.vtu");
  const CellValues written = cell_values(grid);
  REQUIRE(written.size() == 6);
  for (LocalIndex t = 6; t < 12; ++t)
    CHECK(written.at(whole.tets.gid[t]) == all.at(whole.tets.gid[t]));
  // Only the 8 nodes of the right hexahedron: the ghost tet's nodes at x = 0 are left out.
  std::set<GlobalId> referenced;
  for (LocalIndex t = 6; t < 12; ++t)
    for (int c = 0; c < 4; ++c) referenced.insert(whole.nodes.gid[whole.tets.nodes[4 * t + c]]);
  REQUIRE(referenced.size() == 8);
  REQUIRE(grid->GetNumberOfPoints() == 8);
  vtkDataArray* node_gid = grid->GetPointData()->GetArray("gid");
  std::set<GlobalId> points;
  for (vtkIdType p = 0; p < grid->GetNumberOfPoints(); ++p)
    points.insert(static_cast<GlobalId>(node_gid->GetComponent(p, 0)));
  CHECK(points == referenced);
}

TEST_CASE("series on 1 and 3 ranks: only rank 0 writes the .pvd, which lists .vtu or .pvtu",
          "[io][vtk]") {
  TempDir dir;
  const Model m = two_block_model();
  SECTION("three ranks") {
    std::vector<fdem::SeriesWriter> series;
    for (int r = 0; r < 3; ++r) series.emplace_back(dir / "out", "frames", r, 3);
    const std::vector<int> owner = {0, 0, 2, 2, 0, 0, 2, 2, 0, 0, 2, 2};
    for (int frame = 0; frame < 2; ++frame) {
      // Ranks 1 and 2 first: until rank 0 adds the frame there is no .pvd.
      for (int r : {1, 2, 0}) {
        const std::string stem = series[r].next_frame_path();
        CHECK(stem == "frames/frames_00000" + std::to_string(frame));
        Model local = m;
        local.tets.owned.assign(12, 0);
        for (LocalIndex t = 0; t < 12; ++t) local.tets.owned[t] = owner[t] == r;
        fdem::write_parallel_tet_frame(dir / ("out/" + stem), local, kFields, extra_fields(m), r,
                                       3);
        series[r].add_frame(0.25 * frame, series[r].frame_file(stem, "vtu"));
        if (frame == 0 && r != 0) CHECK_FALSE(fs::exists(dir / "out/frames.pvd"));
      }
    }
    const auto files = pvd_files(dir / "out/frames.pvd");
    REQUIRE(files ==
            std::vector<std::string>{"frames/frames_000000.pvtu", "frames/frames_000001.pvtu"});
    CHECK_THAT(read_text(dir / "out/frames.pvd"), Contains("timestep=\"0.25\""));
    for (const std::string& file : files) {
      auto grid = read_pvtu(dir / ("out/" + file));
      CHECK(grid->GetNumberOfCells() == 12);
    }
    CHECK(fs::exists(dir / "out/frames/frames_000001_1.vtu"));  // rank 1's empty piece
    CHECK(temporary_files(dir.path()) == 0);
  }
  SECTION("one rank") {
    fdem::SeriesWriter series(dir / "out", "frames");
    CHECK(series.ranks() == 1);
    const std::string stem = series.next_frame_path();
    fdem::write_parallel_tet_frame(dir / ("out/" + stem), m, kFields, {}, 0, 1);
    series.add_frame(0.0, series.frame_file(stem, "vtu"));
    REQUIRE(pvd_files(dir / "out/frames.pvd") ==
            std::vector<std::string>{"frames/frames_000000.vtu"});
    CHECK(read_vtu(dir / "out/frames/frames_000000.vtu")->GetNumberOfCells() == 12);
  }
  CHECK(fdem::frame_file_name("a/b", "vtp", 1) == "a/b.vtp");
  CHECK(fdem::frame_file_name("a/b", "vtp", 2) == "a/b.pvtp");
}

namespace {

vtkSmartPointer<vtkPolyData> read_pvtp(const std::string& path) {
  vtkNew<vtkXMLPPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  return reader->GetOutput();
}

}  // namespace

TEST_CASE("contact points on 3 ranks: one .pvtp with every rank's points", "[io][vtk]") {
  TempDir dir;
  // Rank r's points: point i of rank r at (r, i, 0.5 i) with force (10 r + i, −i, 2) and tag 10 r +
  // i.
  const std::vector<int> counts = {2, 0, 3};
  std::vector<fdem::SeriesWriter> series;
  for (int r = 0; r < 3; ++r) series.emplace_back(dir.path().string(), "contacts", r, 3);
  for (int r = 0; r < 3; ++r) {
    std::vector<double> points, force, tag;
    for (int i = 0; i < counts[r]; ++i) {
      for (double x : {double(r), double(i), 0.5 * i}) points.push_back(x);
      for (double f : {10.0 * r + i, -double(i), 2.0}) force.push_back(f);
      tag.push_back(10.0 * r + i);
    }
    const std::string stem = series[r].next_frame_path();
    fdem::write_parallel_point_frame(
        dir / stem, points, {{"normal_force", 3, false, force}, {"tag", 1, false, tag}}, r, 3);
    series[r].add_frame(0.5, series[r].frame_file(stem, "vtp"));
  }
  REQUIRE(pvd_files(dir / "contacts.pvd") ==
          std::vector<std::string>{"contacts/contacts_000000.pvtp"});
  vtkNew<vtkXMLPolyDataReader> empty_reader;
  empty_reader->SetFileName((dir / "contacts/contacts_000000_1.vtp").c_str());
  empty_reader->Update();
  CHECK(empty_reader->GetOutput()->GetNumberOfPoints() == 0);
  CHECK(empty_reader->GetOutput()->GetPointData()->GetArray("normal_force"));

  auto poly = read_pvtp(dir / "contacts/contacts_000000.pvtp");
  REQUIRE(poly->GetNumberOfPoints() == 5);
  CHECK(poly->GetNumberOfVerts() == 5);
  vtkDataArray* force = poly->GetPointData()->GetArray("normal_force");
  vtkDataArray* tag = poly->GetPointData()->GetArray("tag");
  REQUIRE(force);
  REQUIRE(tag);
  std::set<int> tags;
  for (vtkIdType p = 0; p < 5; ++p) {
    const int t = static_cast<int>(tag->GetComponent(p, 0));
    const int r = t / 10, i = t % 10;
    tags.insert(t);
    double x[3];
    poly->GetPoint(p, x);
    CHECK(x[0] == r);
    CHECK(x[1] == i);
    CHECK(x[2] == 0.5 * i);
    CHECK(tuple(force, p) == std::vector<double>{10.0 * r + i, -double(i), 2.0});
  }
  CHECK(tags == std::set<int>{0, 1, 20, 21, 22});
  CHECK(temporary_files(dir.path()) == 0);
}

TEST_CASE("crack triangles on 3 ranks, rank 0 empty: one .pvtp with every triangle", "[io][vtk]") {
  TempDir dir;
  // Rank r writes r triangles; triangle i of rank r has corners (r, i, 0) + unit axes, opening
  // 0.1 r + 0.01 i and mode r.
  std::vector<fdem::SeriesWriter> series;
  for (int r = 0; r < 3; ++r) series.emplace_back(dir.path().string(), "cracks", r, 3);
  for (int r = 0; r < 3; ++r) {
    std::vector<double> points, opening, mode;
    std::vector<std::int64_t> triangles;
    for (int i = 0; i < r; ++i) {
      const double corner[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
      for (int c = 0; c < 3; ++c) {
        triangles.push_back(static_cast<std::int64_t>(points.size() / 3));
        points.push_back(r + corner[c][0]);
        points.push_back(i + corner[c][1]);
        points.push_back(corner[c][2]);
      }
      opening.push_back(0.1 * r + 0.01 * i);
      mode.push_back(r);
    }
    const std::string stem = series[r].next_frame_path();
    fdem::write_parallel_triangle_frame(dir / stem, points, triangles,
                                        {{"opening", 1, true, opening}, {"mode", 1, true, mode}}, r,
                                        3);
    series[r].add_frame(1.0, series[r].frame_file(stem, "vtp"));
  }
  REQUIRE(pvd_files(dir / "cracks.pvd") == std::vector<std::string>{"cracks/cracks_000000.pvtp"});
  const std::string summary = read_text(dir / "cracks/cracks_000000.pvtp");
  CHECK_THAT(summary, Contains("PCellData") && Contains("\"opening\"") && Contains("\"mode\""));
  auto poly = read_pvtp(dir / "cracks/cracks_000000.pvtp");
  REQUIRE(poly->GetNumberOfCells() == 3);
  REQUIRE(poly->GetNumberOfPolys() == 3);
  vtkDataArray* opening = poly->GetCellData()->GetArray("opening");
  vtkDataArray* mode = poly->GetCellData()->GetArray("mode");
  REQUIRE(opening);
  REQUIRE(mode);
  std::multiset<double> openings, expected;
  for (int r = 0; r < 3; ++r)
    for (int i = 0; i < r; ++i) expected.insert(0.1 * r + 0.01 * i);
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < 3; ++c) {
    const int r = static_cast<int>(mode->GetComponent(c, 0));
    const double o = opening->GetComponent(c, 0);
    openings.insert(o);
    const int i = static_cast<int>(std::lround((o - 0.1 * r) / 0.01));
    poly->GetCellPoints(c, ids);
    REQUIRE(ids->GetNumberOfIds() == 3);
    double x[3];
    poly->GetPoint(ids->GetId(1), x);
    CHECK(x[0] == r + 1.0);
    CHECK(x[1] == i);
    CHECK(x[2] == 0.0);
  }
  CHECK(openings == expected);
  CHECK(temporary_files(dir.path()) == 0);
}
