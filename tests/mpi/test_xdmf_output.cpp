// Collective XDMF frames on 1–4 ranks: a distributed model written by RunFiles as one HDF5 file
// per frame is read back (serially, on rank 0) and compared with the whole model exactly: every
// node's row (gid, position, displacement, velocity, extra field), every tet's connectivity as
// node gids, its piece, body, material and stress; the .xdmf is well-formed XML (VTK's XML parser)
// and every DataItem names an existing dataset of that type and shape.
// Only CHECK here (no REQUIRE): a rank leaving a test case early would skip its collectives.
#include <hdf5.h>
#include <unistd.h>
#include <vtkNew.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/frame_arrays.hpp"
#include "drivers/run_files.hpp"
#include "drivers/scene_builders.hpp"
#include "parallel/communicator.hpp"
#include "parallel/distribution.hpp"
#include "parallel/xdmf_output.hpp"
#include "shared_temp_dir.hpp"

using namespace fdem;
namespace fs = std::filesystem;

namespace {

// Two bodies of two materials, moved and spun a little so that positions, velocities and stresses
// differ from node to node and tet to tet (the same on every rank).
Model test_model(GlobalId gid_offset = 0) {
  Scene scene = builders::basic_scene(1.0);
  scene.parallel.gid_offset = gid_offset;
  scene.materials = {
      builders::elastic_material(1000, 1e6, 0.3),
      builders::elastic_material(2000, 5e6, 0.25, ElasticModel::st_venant_kirchhoff)};
  scene.materials[1].name = "stiff";
  scene.bodies = {builders::box_body("slab", {0, 0, 0}, {1, 0.6, 0.2}, 6, 4, 2, 0),
                  builders::box_body("post", {0.2, 0.2, 0.3}, {0.4, 0.4, 1.0}, 2, 2, 5, 1)};
  Model model = build_model(scene, load_body_meshes(scene));
  NodeArrays& n = model.nodes;
  for (LocalIndex i = 0; i < n.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double g = static_cast<double>(n.gid[i]);
      n.x[3 * i + k] = n.x0(i)[k] * (1.0 + 0.01 * k) + 1e-3 * std::sin(0.7 * g + k);
      n.v[3 * i + k] = std::cos(0.3 * g - k);
    }
  return model;
}

double point_extra(GlobalId gid) {
  return 273.15 + 0.5 * static_cast<double>(gid);
}
double cell_extra(GlobalId gid) {
  return 1.0 / (1.0 + static_cast<double>(gid));
}

template <class T>
hid_t memory_type() {
  if constexpr (std::is_same_v<T, double>)
    return H5T_NATIVE_DOUBLE;
  else if constexpr (std::is_same_v<T, std::int32_t>)
    return H5T_NATIVE_INT32;
  else
    return H5T_NATIVE_INT64;
}

// A whole dataset (serial HDF5); `dims` gets its shape.  Empty when it is missing.
template <class T>
std::vector<T> read(hid_t file, const std::string& path, std::vector<hsize_t>* dims = nullptr) {
  if (H5Lexists(file, path.substr(0, path.rfind('/')).c_str(), H5P_DEFAULT) <= 0 ||
      H5Lexists(file, path.c_str(), H5P_DEFAULT) <= 0)
    return {};
  const hid_t set = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  const hid_t space = H5Dget_space(set);
  std::vector<hsize_t> shape(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)));
  H5Sget_simple_extent_dims(space, shape.data(), nullptr);
  std::vector<T> values(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
  if (!values.empty()) H5Dread(set, memory_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
  H5Sclose(space);
  H5Dclose(set);
  if (dims) *dims = shape;
  return values;
}

template <class T>
T attribute(hid_t file, const char* name) {
  T value{};
  const hid_t a = H5Aopen(file, name, H5P_DEFAULT);
  H5Aread(a, memory_type<T>(), &value);
  H5Aclose(a);
  return value;
}

// Checks frame file `path` against `global` (the whole model at the written state).
void check_frame(const std::string& path, const Model& global, double time) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  CHECK(file >= 0);
  if (file < 0) return;
  const NodeArrays& gn = global.nodes;
  const TetArrays& gt = global.tets;
  CHECK(attribute<double>(file, "time") == time);
  CHECK(attribute<std::int64_t>(file, "n_nodes") == gn.size());
  CHECK(attribute<std::int64_t>(file, "n_tets") == gt.size());

  // Nodes: every gid once, with its exact values.
  const auto node_gid = read<std::int64_t>(file, "/nodes/gid");
  const auto xyz = read<double>(file, "/nodes/xyz");
  const auto u = read<double>(file, "/nodes/displacement");
  const auto v = read<double>(file, "/nodes/velocity");
  const auto temperature = read<double>(file, "/nodes/temperature");
  CHECK(node_gid.size() == static_cast<std::size_t>(gn.size()));
  CHECK(xyz.size() == 3 * node_gid.size());
  CHECK(u.size() == xyz.size());
  CHECK(v.size() == xyz.size());
  CHECK(temperature.size() == node_gid.size());
  std::map<GlobalId, LocalIndex> node_of;  // gid → index in the global model
  for (LocalIndex i = 0; i < gn.size(); ++i) node_of[gn.gid[i]] = i;
  std::vector<int> seen(node_gid.size(), 0);
  long wrong_nodes = 0;
  for (std::size_t r = 0; r < node_gid.size() && xyz.size() == 3 * node_gid.size(); ++r) {
    const auto it = node_of.find(node_gid[r]);
    if (it == node_of.end() || seen[static_cast<std::size_t>(it->second)]++) {
      ++wrong_nodes;
      continue;
    }
    const auto i = static_cast<std::size_t>(it->second);
    for (int k = 0; k < 3; ++k)
      wrong_nodes += xyz[3 * r + k] != gn.x[3 * i + k] ||
                     u[3 * r + k] != gn.x[3 * i + k] - gn.x0(i)[k] ||
                     v[3 * r + k] != gn.v[3 * i + k];
    wrong_nodes += temperature[r] != point_extra(node_gid[r]);
  }
  CHECK(wrong_nodes == 0);

  // Tets: every gid once; connectivity (rows of /nodes) gives the model's node gids in order.
  const auto tet_gid = read<std::int64_t>(file, "/tets/gid");
  std::vector<hsize_t> conn_dims;
  const auto conn = read<std::int64_t>(file, "/tets/connectivity", &conn_dims);
  const auto piece = read<std::int32_t>(file, "/tets/piece");
  const auto body = read<std::int32_t>(file, "/tets/body");
  const auto material = read<std::int32_t>(file, "/tets/material");
  const auto stress = read<double>(file, "/tets/stress");
  const auto mises = read<double>(file, "/tets/von_mises");
  const auto damage = read<double>(file, "/tets/damage");
  CHECK(tet_gid.size() == static_cast<std::size_t>(gt.size()));
  CHECK(conn_dims == std::vector<hsize_t>{tet_gid.size(), 4});
  CHECK(stress.size() == 9 * tet_gid.size());
  CHECK((piece.size() == tet_gid.size() && body.size() == tet_gid.size() &&
         material.size() == tet_gid.size() && mises.size() == tet_gid.size() &&
         damage.size() == tet_gid.size()));
  std::vector<LocalIndex> all_tets(static_cast<std::size_t>(gt.size()));
  for (LocalIndex t = 0; t < gt.size(); ++t) all_tets[static_cast<std::size_t>(t)] = t;
  // The one-rank arrays of the whole model: stress must come out bit for bit the same.
  const std::vector<FrameArray> one_rank = tet_frame_arrays(global, all_tets, {}, {"stress"}, {});
  const FrameArray* sigma = nullptr;
  const FrameArray* von_mises = nullptr;
  for (const FrameArray& a : one_rank) {
    if (a.name == "stress") sigma = &a;
    if (a.name == "von_mises") von_mises = &a;
  }
  std::map<GlobalId, LocalIndex> tet_of;
  for (LocalIndex t = 0; t < gt.size(); ++t) tet_of[gt.gid[t]] = t;
  std::vector<int> tet_seen(tet_gid.size(), 0);
  long wrong_tets = 0;
  const bool shapes_ok = conn.size() == 4 * tet_gid.size() && stress.size() == 9 * tet_gid.size() &&
                         damage.size() == tet_gid.size() && material.size() == tet_gid.size();
  for (std::size_t r = 0; r < tet_gid.size() && shapes_ok && sigma && von_mises; ++r) {
    const auto it = tet_of.find(tet_gid[r]);
    if (it == tet_of.end() || tet_seen[static_cast<std::size_t>(it->second)]++) {
      ++wrong_tets;
      continue;
    }
    const auto t = static_cast<std::size_t>(it->second);
    for (int c = 0; c < 4; ++c) {
      const std::int64_t row = conn[4 * r + c];
      wrong_tets += row < 0 || row >= static_cast<std::int64_t>(node_gid.size()) ||
                    node_gid[static_cast<std::size_t>(row)] != gn.gid[gt.nodes[4 * t + c]];
    }
    wrong_tets += piece[r] != gt.piece[t] || material[r] != gt.material[t] ||
                  body[r] != global.pieces[gt.piece[t]].body;
    for (int k = 0; k < 9; ++k) wrong_tets += stress[9 * r + k] != sigma->real[9 * t + k];
    wrong_tets += mises[r] != von_mises->real[t] || damage[r] != cell_extra(tet_gid[r]);
  }
  CHECK(wrong_tets == 0);
  // Two bodies of two materials, both present.
  CHECK(std::count(body.begin(), body.end(), 1) > 0);
  CHECK(std::count(material.begin(), material.end(), 0) > 0);
  H5Fclose(file);
}

std::vector<std::string> words(const char* text) {
  std::istringstream in(text ? text : "");
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// Every DataItem of the .xdmf: "file:/path" names an existing dataset whose shape is Dimensions
// and whose type is DataType/Precision.  Returns the number of DataItems checked.
int check_data_items(vtkXMLDataElement* e, const fs::path& directory, long& wrong) {
  int items = 0;
  if (std::string(e->GetName()) == "DataItem") {
    ++items;
    const std::string text = e->GetCharacterData() ? e->GetCharacterData() : "";
    const std::string reference = words(text.c_str()).empty() ? "" : words(text.c_str())[0];
    const auto colon = reference.find(':');
    const std::string file = (directory / reference.substr(0, colon)).string();
    const std::string dataset = colon == std::string::npos ? "" : reference.substr(colon + 1);
    const hid_t h5 = fs::exists(file) ? H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT) : -1;
    if (h5 < 0 || H5Lexists(h5, dataset.c_str(), H5P_DEFAULT) <= 0) {
      ++wrong;
      UNSCOPED_INFO("missing dataset " << reference);
    } else {
      const hid_t set = H5Dopen2(h5, dataset.c_str(), H5P_DEFAULT);
      const hid_t space = H5Dget_space(set), type = H5Dget_type(set);
      std::vector<hsize_t> dims(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)));
      H5Sget_simple_extent_dims(space, dims.data(), nullptr);
      std::vector<std::string> expected;
      for (hsize_t d : dims) expected.push_back(std::to_string(d));
      const bool is_float = H5Tget_class(type) == H5T_FLOAT;
      const std::string data_type = e->GetAttribute("DataType") ? e->GetAttribute("DataType") : "";
      const std::string precision =
          e->GetAttribute("Precision") ? e->GetAttribute("Precision") : "";
      const bool ok =
          words(e->GetAttribute("Dimensions")) == expected &&
          data_type == (is_float ? "Float" : "Int") &&
          precision == std::to_string(H5Tget_size(type)) &&
          std::string(e->GetAttribute("Format") ? e->GetAttribute("Format") : "") == "HDF";
      if (!ok) {
        ++wrong;
        UNSCOPED_INFO("DataItem " << reference << " does not match its dataset");
      }
      H5Tclose(type);
      H5Sclose(space);
      H5Dclose(set);
    }
    if (h5 >= 0) H5Fclose(h5);
  }
  for (int i = 0; i < e->GetNumberOfNestedElements(); ++i)
    items += check_data_items(e->GetNestedElement(i), directory, wrong);
  return items;
}

}  // namespace

TEST_CASE("xdmf frames: every node and tet of a distributed model, exactly, in one HDF5 file",
          "[mpi][xdmf]") {
  // Gids from 0, and from above 2^32 (parallel.gid_offset): written as int64, not truncated.
  const GlobalId offset = GENERATE(GlobalId{0}, (GlobalId{1} << 32) + 12345);
  INFO("gid offset " << offset);
  const Communicator comm = Communicator::world();
  const SharedTempDir dir(comm, "xdmf");
  Model global = test_model(offset);
  CHECK(global.nodes.gid.front() == offset);

  // This rank's part with its halo (ghost nodes of owned tets are owned by other ranks).
  TravellingState whole, local_state;
  whole.x_at_detection = global.nodes.x;
  Model local;
  const Distribution distribution(comm, DistributionSettings{}, global, whole, 0.0, {}, local,
                                  local_state);
  CHECK(local.tets.n_owned > 0);
  if (comm.size() > 1) CHECK(local.nodes.size() > local.nodes.n_owned);  // there are ghosts

  RunFiles files(dir.path(), {"displacement", "velocity", "stress"}, comm.rank(), comm.size(),
                 XdmfFrames{&comm, {{"romio_cb_write", "enable"}, {"striping_factor", "4"}}});
  const auto extras = [](const Model& m) {
    std::vector<double> temperature, damage;
    for (LocalIndex i = 0; i < m.nodes.size(); ++i)
      temperature.push_back(point_extra(m.nodes.gid[i]));
    for (LocalIndex t = 0; t < m.tets.size(); ++t) damage.push_back(cell_extra(m.tets.gid[t]));
    return std::vector<FrameField>{{"temperature", 1, false, temperature},
                                   {"damage", 1, true, damage}};
  };
  files.write_frame(0.0, local, extras(local), nullptr, distribution.node_owners());
  // A second frame after a move of every node (the ghosts too, as the halo exchange does).
  for (Model* m : {&global, &local})
    for (LocalIndex i = 0; i < m->nodes.size(); ++i)
      for (int k = 0; k < 3; ++k) m->nodes.x[3 * i + k] += 1e-3 * ((3 * m->nodes.gid[i] + k) % 7);
  files.write_frame(0.25, local, extras(local), nullptr, distribution.node_owners());

  if (comm.is_root()) {
    const fs::path out(dir.path());
    CHECK(fs::exists(out / "frames/frames_000000.h5"));
    CHECK(fs::exists(out / "frames/frames_000001.h5"));
    CHECK_FALSE(fs::exists(out / "frames.pvd"));  // no .vtu frames besides
    CHECK(std::distance(fs::directory_iterator(out / "frames"), fs::directory_iterator{}) == 2);
    check_frame((out / "frames/frames_000001.h5").string(), global, 0.25);

    vtkNew<vtkXMLDataParser> parser;
    const std::string xdmf = (out / "frames.xdmf").string();
    parser->SetFileName(xdmf.c_str());
    CHECK(parser->Parse() == 1);
    vtkXMLDataElement* root = parser->GetRootElement();
    CHECK(root != nullptr);
    if (root) {
      CHECK(std::string(root->GetName()) == "Xdmf");
      CHECK(std::string(root->GetAttribute("Version")) == "3.0");
      vtkXMLDataElement* domain = root->FindNestedElementWithName("Domain");
      vtkXMLDataElement* series = domain ? domain->FindNestedElementWithName("Grid") : nullptr;
      CHECK(series != nullptr);
      if (series) {
        CHECK(std::string(series->GetAttribute("CollectionType")) == "Temporal");
        CHECK(series->GetNumberOfNestedElements() == 2);
        vtkXMLDataElement* last = series->GetNestedElement(1);
        vtkXMLDataElement* when = last->FindNestedElementWithName("Time");
        CHECK((when && std::string(when->GetAttribute("Value")) == "0.25"));
        vtkXMLDataElement* topology = last->FindNestedElementWithName("Topology");
        CHECK((topology && std::string(topology->GetAttribute("TopologyType")) == "Tetrahedron" &&
               std::string(topology->GetAttribute("NumberOfElements")) ==
                   std::to_string(global.tets.size())));
        long wrong = 0;
        // Per frame: topology, geometry, 4 point arrays, 7 cell arrays.
        CHECK(check_data_items(root, out, wrong) == 2 * 13);
        CHECK(wrong == 0);
      }
    }
  }
}

TEST_CASE("xdmf frames: an unwritable frame file is an IoError on every rank naming it",
          "[mpi][xdmf]") {
  const Communicator comm = Communicator::world();
  XdmfFrameRows rows;  // nothing to write: the file creation fails first
  std::string message;
  try {
    write_xdmf_frame("/nonexistent-fdem-dir", "frames/frames_000000.h5", 0.0, comm, rows);
  } catch (const IoError& e) {
    message = e.what();
  }
  CHECK_THAT(message, Catch::Matchers::Contains(
                          "frame '/nonexistent-fdem-dir/frames/frames_000000.h5': cannot create"));
  CHECK_FALSE(fs::exists("/nonexistent-fdem-dir"));
}

TEST_CASE("MPI-IO hints: FDEM_MPIIO_HINTS adds to and overrides the scene's", "[mpi][xdmf]") {
  const MpiIoHints scene{{"striping_factor", "16"}, {"romio_cb_write", "enable"}};
  CHECK(merge_mpi_io_hints(scene, nullptr) == scene);
  CHECK(merge_mpi_io_hints(scene, " striping_factor=64 , cb_nodes=8,") ==
        MpiIoHints{{"striping_factor", "64"}, {"romio_cb_write", "enable"}, {"cb_nodes", "8"}});
  CHECK_THROWS_WITH(merge_mpi_io_hints({}, "striping_factor"),
                    Catch::Matchers::StartsWith("FDEM_MPIIO_HINTS: 'striping_factor' is not "
                                                "key=value"));
}
