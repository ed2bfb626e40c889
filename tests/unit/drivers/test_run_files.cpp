// The output files one at a time: summary_json for a hand-made report (every value, escaping,
// non-finite numbers), energy.csv / bodies.csv rows for a known motion of a generated box, and
// frames.pvd + .vtu for known displacements.
#include <unistd.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "core/model_builder.hpp"
#include "drivers/mesh_generators.hpp"
#include "drivers/run_files.hpp"
#include "drivers/simulation.hpp"
#include "io/scene_reader.hpp"
#include "json_test_support.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using fdem_test::Json;

namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::vector<std::string>> read_csv(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::stringstream text(read_text(path));
  for (std::string line; std::getline(text, line);) {
    if (line.empty()) continue;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    rows.push_back(cells);
  }
  return rows;
}

class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "fdem_files_XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot create a temp directory");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

// A model with the given counts only (summary_json reads nothing else).
fdem::Model model_with_counts(int nodes, int tets, int pieces) {
  fdem::Model m;
  m.nodes.gid.resize(nodes);
  m.tets.gid.resize(tets);
  m.pieces.add_body(pieces);
  return m;
}

fdem::RunReport sample_report() {
  fdem::RunReport r;
  r.status = "completed";
  r.steps = 1200;
  r.time = 0.012;
  r.time_step = 1.0e-5;
  r.critical_time_step = 2.0e-5;
  r.wall_seconds = 4.0;
  r.energy.kinetic = 1.5;
  r.energy.strain = 2.25;
  r.energy.gravity = -3.5;
  r.energy.contact = 0.125;
  r.energy.joint = 0.0625;
  r.energy.dissipated_fracture = 0.03125;
  r.energy.dissipated_friction = 0.5;
  r.energy.dissipated_damping = 0.75;
  r.energy.external_work = 1.75;
  r.balance_error = 3.0e-4;
  r.state_hash = "0123456789abcdef";
  r.nodes = 27;  // counts over all ranks (the model only gives the pieces)
  r.elements = 48;
  r.stages = {{"internal_forces", 1.25, 1200}, {"joint_forces", 0.0, 0}, {"integrate", 0.5, 1200}};
  return r;
}

// A 2 m × 1 m × 1 m box of density 1000 (2000 kg), 2×1×1 cells, read through the scene reader.
fdem::Model box_model() {
  const fdem::Scene scene = fdem::parse_scene(R"(time: {end: 1}
materials:
  rock: {density: 1000, elastic: {young: 1e6, poisson: 0.25}}
bodies:
  - name: slab
    mesh: {box: {min: [0, 0, 0], max: [2, 1, 1], cells: [2, 1, 1]}}
    material: rock
)",
                                              "slab.yaml");
  return fdem::build_model(scene, fdem::load_body_meshes(scene));
}

}  // namespace

TEST_CASE("summary_json holds every value of the report and the model counts", "[cli]") {
  const fdem::Model model = model_with_counts(27, 48, 3);
  const Json s = fdem_test::parse_json(fdem::summary_json(sample_report(), model, "two-blocks"));
  CHECK(s["scene"].str() == "two-blocks");
  CHECK(s["status"].str() == "completed");
  CHECK_FALSE(s.has("reason"));
  CHECK(s["ranks"].num() == 1);
  CHECK(s["steps"].num() == 1200);
  CHECK(s["end_time"].num() == 0.012);
  CHECK(s["time_step"].num() == 1.0e-5);
  CHECK(s["critical_time_step"].num() == 2.0e-5);
  CHECK(s["wall_seconds"].num() == 4.0);
  CHECK(s["nodes"].num() == 27);
  CHECK(s["elements"].num() == 48);
  CHECK(s["pieces"].num() == 3);
  CHECK(s["joints"].num() == 0);
  CHECK(s["broken_joints"].num() == 0);
  const Json& stages = s["stages"];
  CHECK(stages.members.size() == 2);  // joint_forces never ran
  CHECK(stages["internal_forces"]["seconds"].num() == 1.25);
  CHECK(stages["internal_forces"]["calls"].num() == 1200);
  CHECK(stages["integrate"]["seconds"].num() == 0.5);
  CHECK(s["throughput"]["element_steps_per_second"].num() == Approx(48.0 * 1200 / 4.0));
  const Json& e = s["energy"];
  CHECK(e["kinetic"].num() == 1.5);
  CHECK(e["strain"].num() == 2.25);
  CHECK(e["gravity"].num() == -3.5);
  CHECK(e["contact"].num() == 0.125);
  CHECK(e["joint"].num() == 0.0625);
  CHECK(e["dissipated_fracture"].num() == 0.03125);
  CHECK(e["dissipated_friction"].num() == 0.5);
  CHECK(e["dissipated_damping"].num() == 0.75);
  CHECK(e["external_work"].num() == 1.75);
  CHECK(e["balance_error"].num() == 3.0e-4);
  CHECK(s["state_hash"].str() == "0123456789abcdef");
  CHECK_FALSE(s.has("decomposition"));  // one rank
}

TEST_CASE("summary_json of an N-rank run reports the decomposition", "[cli]") {
  fdem::RunReport r = sample_report();
  r.ranks = 2;
  r.parallel = true;
  r.imbalance = 1.05;
  r.max_imbalance = 1.25;
  r.redistributions = 14;
  r.rebalances = 2;
  r.migrated_elements = 430;
  r.halo_elements_max = 120;
  r.ghost_nodes_max = 64;
  r.ghost_nodes_mean = 60;
  r.neighbours_max = 1;
  r.active_elements_max = 150;
  r.communication_seconds = 0.5;
  r.exchanged_ghosts_max = 40;
  r.migration.incremental_cycles = 11;
  r.migration.sent_tets = 900;
  r.migration.sent_bytes = 198000;
  r.migration.repartition_seconds = 0.25;
  r.migration.predicted_gain_seconds = 1.5;
  r.migration.repartitions_declined = 4;
  r.joints = 10;
  r.broken_joints = 3;
  r.broken_by_mode[0] = 2;
  r.broken_by_mode[2] = 1;
  const Json s = fdem_test::parse_json(fdem::summary_json(r, model_with_counts(0, 0, 3), "wall"));
  CHECK(s["ranks"].num() == 2);
  CHECK(s["elements"].num() == 48);
  CHECK(s["joints"].num() == 10);
  CHECK(s["broken_joints"].num() == 3);
  CHECK(s["broken_by_mode"]["tension"].num() == 2);
  CHECK(s["broken_by_mode"]["mixed"].num() == 1);
  const Json& d = s["decomposition"];
  CHECK(d["imbalance"].num() == 1.05);
  CHECK(d["max_imbalance"].num() == 1.25);
  CHECK(d["redistributions"].num() == 14);
  CHECK(d["rebalances"].num() == 2);
  CHECK(d["migrated_elements"].num() == 430);
  CHECK(d["halo_elements_max"].num() == 120);
  CHECK(d["ghost_nodes_max"].num() == 64);
  CHECK(d["ghost_nodes_mean"].num() == 60);
  CHECK(d["neighbours_max"].num() == 1);
  CHECK(d["active_elements_max"].num() == 150);
  CHECK(d["communication_seconds"].num() == 0.5);
  CHECK(d["ghost_nodes_exchanged_max"].num() == 40);
  CHECK(d["incremental_redistributions"].num() == 11);
  CHECK(d["sent_elements"].num() == 900);
  CHECK(d["sent_bytes"].num() == 198000);
  CHECK(d["repartition_seconds"].num() == 0.25);
  CHECK(d["predicted_gain_seconds"].num() == 1.5);
  CHECK(d["repartitions_declined"].num() == 4);
}

TEST_CASE("summary_json of a failed run is valid JSON with the reason", "[cli]") {
  fdem::RunReport r = sample_report();
  r.status = "failed";
  r.reason = "numerical failure at step 7: body \"wall\" \\ stone\nsecond line\ttab";
  r.wall_seconds = 0.0;
  const fdem::Model model = model_with_counts(4, 1, 1);
  const Json s = fdem_test::parse_json(fdem::summary_json(r, model, "say \"hi\""));
  CHECK(s["scene"].str() == "say \"hi\"");
  CHECK(s["status"].str() == "failed");
  CHECK_THAT(s["reason"].str(), Contains("body \"wall\" \\ stone\nsecond line"));
  CHECK(s["throughput"]["element_steps_per_second"].num() == 0.0);  // no division by zero

  SECTION("non-finite energies (a run that blew up) are written as null") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    r.energy.kinetic = nan;
    r.energy.strain = inf;
    r.energy.gravity = -inf;
    r.balance_error = nan;
    const std::string text = fdem::summary_json(r, model, "blow-up");
    INFO(text);
    const Json b = fdem_test::parse_json(text);  // throws on "nan" / "inf"
    CHECK(b["energy"]["kinetic"].type == Json::Type::null);
    CHECK(b["energy"]["strain"].type == Json::Type::null);
    CHECK(b["energy"]["gravity"].type == Json::Type::null);
    CHECK(b["energy"]["balance_error"].type == Json::Type::null);
    CHECK(b["energy"]["contact"].num() == 0.125);
  }
}

TEST_CASE("RunFiles writes energy and body rows as they come, and frames", "[cli]") {
  TempDir dir;
  fdem::Model model = box_model();
  REQUIRE(model.pieces.size() == 1);
  REQUIRE(model.nodes.size() == 12);
  REQUIRE(model.tets.size() == 12);
  fdem::RunFiles files(dir / "out", {"displacement", "velocity", "stress"});

  fdem::EnergyTerms e;
  e.kinetic = 1.25;
  e.strain = 0.5;
  e.gravity = -0.25;
  e.external_work = 0.125;
  files.write_energy_row(0.001, e, 2.5e-7);
  // Rows are flushed at once, so a run that dies keeps its history.
  auto energy = read_csv(dir / "out/energy.csv");
  REQUIRE(energy.size() == 2);
  CHECK(energy[0].size() == 13);
  // dissipated_boundary, added after the first release, is the last column.
  CHECK(energy[1] == std::vector<std::string>{"0.001", "1.25", "0.5", "-0.25", "0", "0", "0", "0",
                                              "0", "0.125", "1.375", "2.5e-07", "0"});

  files.write_bodies_rows(0.0, model, fdem::piece_motions(model));
  files.write_frame(0.0, model);
  // Translate by (0.1, −0.2, 0.3) m, rotate by 0.05 rad about z through the centroid (1, 0.5,
  // 0.5), and give every node the velocity (1, 2, 3) m/s.
  const double angle = 0.05, c = std::cos(angle), s = std::sin(angle);
  for (int n = 0; n < model.nodes.size(); ++n) {
    const double x = model.nodes.x0(n)[0] - 1.0, y = model.nodes.x0(n)[1] - 0.5;
    model.nodes.x[3 * n] = 1.0 + c * x - s * y + 0.1;
    model.nodes.x[3 * n + 1] = 0.5 + s * x + c * y - 0.2;
    model.nodes.x[3 * n + 2] = model.nodes.x0(n)[2] + 0.3;
    for (int k = 0; k < 3; ++k) model.nodes.v[3 * n + k] = k + 1.0;
  }
  files.write_bodies_rows(0.5, model, fdem::piece_motions(model));
  files.write_frame(0.5, model);

  const auto bodies = read_csv(dir / "out/bodies.csv");
  REQUIRE(bodies.size() == 3);
  const auto number = [&](int row, int col) { return std::stod(bodies[row][col]); };
  CHECK(bodies[1][0] == "0");
  CHECK(bodies[1][1] == "slab");
  CHECK(bodies[1][2] == "0");
  CHECK(number(1, 3) == Approx(2000.0).epsilon(1e-12));  // 1000 kg/m^3 × 2 m^3
  CHECK(number(1, 4) == Approx(1.0).epsilon(1e-12));
  CHECK(number(1, 5) == Approx(0.5).epsilon(1e-12));
  CHECK(number(1, 6) == Approx(0.5).epsilon(1e-12));
  for (int k = 7; k < 13; ++k) CHECK(number(1, k) == Approx(0.0).margin(1e-12));
  CHECK(number(2, 0) == 0.5);
  CHECK(number(2, 4) == Approx(1.1).epsilon(1e-11));
  CHECK(number(2, 5) == Approx(0.3).epsilon(1e-11));
  CHECK(number(2, 6) == Approx(0.8).epsilon(1e-11));
  CHECK(number(2, 7) == Approx(1.0).epsilon(1e-11));
  CHECK(number(2, 8) == Approx(2.0).epsilon(1e-11));
  CHECK(number(2, 9) == Approx(3.0).epsilon(1e-11));
  CHECK(number(2, 10) == Approx(0.0).margin(1e-11));
  CHECK(number(2, 11) == Approx(0.0).margin(1e-11));
  CHECK(number(2, 12) == Approx(angle).epsilon(1e-10));

  const std::string pvd = read_text(dir / "out/frames.pvd");
  CHECK_THAT(pvd, Contains("timestep=\"0\"") && Contains("file=\"frames/frames_000000.vtu\""));
  CHECK_THAT(pvd, Contains("timestep=\"0.5\"") && Contains("file=\"frames/frames_000001.vtu\""));
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName((dir / "out/frames/frames_000001.vtu").c_str());
  reader->Update();
  vtkUnstructuredGrid* grid = reader->GetOutput();
  REQUIRE(grid->GetNumberOfPoints() == 12);
  CHECK(grid->GetNumberOfCells() == 12);
  vtkDataArray* u = grid->GetPointData()->GetArray("displacement");
  vtkDataArray* v = grid->GetPointData()->GetArray("velocity");
  REQUIRE(u);
  REQUIRE(v);
  for (vtkIdType n = 0; n < 12; ++n) {
    for (int k = 0; k < 3; ++k) {
      CHECK(u->GetComponent(n, k) == Approx(model.nodes.x[3 * n + k] - model.nodes.x0(n)[k]));
      CHECK(v->GetComponent(n, k) == k + 1.0);
    }
  }

  fdem::RunReport r = sample_report();
  r.nodes = model.nodes.size();
  files.write_summary(r, model, "slab");
  const Json summary = fdem_test::parse_json(read_text(dir / "out/summary.json"));
  CHECK(summary["nodes"].num() == 12);
  CHECK(summary["scene"].str() == "slab");
}
